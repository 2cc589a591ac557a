#include "apps/support/scenario_file.h"

#include <algorithm>
#include <sstream>
#include <stdexcept>

#include "formats/mesh/read_mesh.h"

namespace quiver::app {

namespace {

std::string trim(const std::string& s) {
  const size_t first = s.find_first_not_of(" \t\r");
  return first == std::string::npos ? std::string() : s.substr(first, s.find_last_not_of(" \t\r") - first + 1);
}

} // namespace

std::vector<std::string> parseScenarioFile(const std::string& text, const std::string& fileName,
                                           const std::vector<std::string>& known) {
  std::vector<std::string> tokens;
  std::istringstream lines(text);
  std::string line;
  for (int number = 1; std::getline(lines, line); ++number) {
    const auto fail = [&](const std::string& what) {
      throw std::runtime_error(fileName + ":" + std::to_string(number) + ": " + what);
    };
    line = trim(line.substr(0, line.find('#')));
    if (line.empty()) continue;
    const size_t equals = line.find('=');
    if (equals == std::string::npos) fail("expected 'name = value', such as 'twist = 60'");
    const std::string name = trim(line.substr(0, equals)), value = trim(line.substr(equals + 1));
    if (std::find(known.begin(), known.end(), name) == known.end()) {
      std::string list;
      for (const std::string& k : known) list += (list.empty() ? "" : ", ") + k;
      fail("'" + name + "' is not a scenario option (" + list + ")");
    }
    if (value.empty()) fail(name + " has no value");
    tokens.push_back("--" + name + "=" + value);
  }
  return tokens;
}

std::vector<std::string> expandScenarioFiles(const std::vector<std::string>& args, const std::vector<std::string>& known) {
  std::vector<std::string> out;
  for (size_t i = 0; i < args.size(); ++i) {
    std::string path;
    if (args[i] == "--scenario") {
      if (i + 1 == args.size()) throw std::runtime_error("--scenario needs a FILE");
      path = args[++i];
    } else if (args[i].rfind("--scenario=", 0) == 0) {
      path = args[i].substr(11);
    } else {
      out.push_back(args[i]);
      continue;
    }
    const std::vector<std::string> tokens = parseScenarioFile(readFileBytes(path), path, known);
    out.insert(out.end(), tokens.begin(), tokens.end());
  }
  return out;
}

} // namespace quiver::app
