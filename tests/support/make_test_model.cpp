// quiver_test_model OUT.qvr: writes tests/support/small_model.h's beam for the suite's fixture.
#include <cstdio>
#include <exception>

#include "tests/support/small_model.h"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: quiver_test_model OUT.qvr\n");
    return 2;
  }
  try {
    quiver::writeModelFile(argv[1], quiver::test::smallBeamModel());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "quiver_test_model: %s\n", e.what());
    return 1;
  }
  return 0;
}
