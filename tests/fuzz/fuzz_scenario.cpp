// libFuzzer target for scenario files (quiver sim/full/render --scenario), under AddressSanitizer
// and UBSan. A std::runtime_error is the only acceptable failure; every accepted token is a known
// option with a value.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <stdexcept>
#include <string>

#include "apps/support/scenario_file.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::vector<std::string> known{"steps", "hold", "group", "force", "drag", "twist", "gravity"};
  std::vector<std::string> tokens;
  try {
    tokens = quiver::app::parseScenarioFile(std::string(reinterpret_cast<const char*>(data), size), "fuzz.txt", known);
  } catch (const std::runtime_error&) {
    return 0;
  }
  for (const std::string& token : tokens) {
    const size_t equals = token.find('=');
    if (token.rfind("--", 0) != 0 || equals == std::string::npos || equals + 1 == token.size()) std::abort();
  }
  return 0;
}
