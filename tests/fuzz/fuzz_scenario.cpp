// libFuzzer target for scenario files (quiver sim/full/render --scenario), under AddressSanitizer
// and UBSan. A std::runtime_error is the only acceptable failure; every token is one the check
// accepted, rebuilt from its name and value.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <vector>

#include "apps/support/scenario_file.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::vector<std::string> accepted;
  const auto check = [&](const std::string& name, const std::string& value) {
    if (name.empty() || name.find_first_of(" \t=#") != std::string::npos) return std::string("not a name");
    accepted.push_back("--" + name + "=" + value);
    return std::string();
  };
  std::vector<std::string> tokens;
  try {
    tokens = quiver::app::parseScenarioFile(std::string(reinterpret_cast<const char*>(data), size), "fuzz.txt", check);
  } catch (const std::runtime_error&) {
    return 0;
  }
  if (tokens != accepted || tokens.empty()) std::abort();
  return 0;
}
