// quiver_test_model OUT.qvr [FREE.qvr]: writes tests/support/small_model.h's beam for the suite's
// fixture, and the same beam baked free (no fixed vertex: it can fly) when asked.
#include <cstdio>
#include <exception>

#include "tests/support/small_model.h"

int main(int argc, char** argv) {
  if (argc != 2 && argc != 3) {
    std::fprintf(stderr, "usage: quiver_test_model OUT.qvr [FREE.qvr]\n");
    return 2;
  }
  try {
    quiver::writeModelFile(argv[1], quiver::test::smallBeamModel());
    if (argc == 3) {
      quiver::test::SmallModelSpec free;
      free.free = true;
      free.rank = 16;
      quiver::writeModelFile(argv[2], quiver::test::smallBeamModel(free));
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "quiver_test_model: %s\n", e.what());
    return 1;
  }
  return 0;
}
