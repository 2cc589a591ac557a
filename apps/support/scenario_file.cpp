#include "apps/support/scenario_file.h"

#include <sstream>
#include <stdexcept>

#include "formats/mesh/read_mesh.h"

namespace quiver::app {

namespace {

std::string trim(const std::string& s) {
  const size_t first = s.find_first_not_of(" \t\r");
  return first == std::string::npos ? std::string() : s.substr(first, s.find_last_not_of(" \t\r") - first + 1);
}

// "--twist=60" and "--twist" both set "twist".
bool sets(const std::string& argument, const std::string& name) {
  const std::string flag = "--" + name;
  return argument == flag || argument.rfind(flag + "=", 0) == 0;
}

} // namespace

std::vector<std::string> parseScenarioFile(const std::string& text, const std::string& fileName, const ScenarioCheck& check) {
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
    if (value.empty()) fail((name.empty() ? "the option" : name) + " has no value");
    if (const std::string problem = check(name, value); !problem.empty()) fail(problem);
    tokens.push_back("--" + name + "=" + value);
  }
  if (tokens.empty()) throw std::runtime_error(fileName + ": sets no scenario option");
  return tokens;
}

std::vector<std::string> expandScenarioFiles(const std::vector<std::string>& args, const ScenarioCheck& check) {
  struct Token {
    std::string text, option;  // option: the name a file's token sets; "" for the command line's own
  };
  std::vector<Token> expanded;
  for (size_t i = 0; i < args.size(); ++i) {
    std::string path;
    if (args[i] == "--scenario") {
      if (i + 1 == args.size()) throw std::runtime_error("--scenario needs a FILE");
      path = args[++i];
    } else if (args[i].rfind("--scenario=", 0) == 0) {
      path = args[i].substr(11);
    } else {
      expanded.push_back({args[i], ""});
      continue;
    }
    for (const std::string& token : parseScenarioFile(readFileBytes(path), path, check))
      expanded.push_back({token, token.substr(2, token.find('=') - 2)});
  }
  std::vector<std::string> out;
  for (size_t i = 0; i < expanded.size(); ++i) {
    bool overridden = false;
    for (size_t j = i + 1; j < expanded.size() && !expanded[i].option.empty() && !overridden; ++j)
      overridden = sets(expanded[j].text, expanded[i].option);
    if (!overridden) out.push_back(expanded[i].text);
  }
  return out;
}

} // namespace quiver::app
