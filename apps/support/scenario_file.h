#pragma once
// Scenario files: the scenario options of `quiver sim`, `full` and `render` kept in a file, so one
// scenario drives all three alike. One option per line, `name = value`, '#' starts a comment:
//
//   group = x>max-1e-6
//   twist = 60        # degrees
//   drag = 0,0.05,0
//   hold = 100
//   gravity = true
//
// `--scenario FILE` stands for those options, at its place on the command line; the same option
// given later on the command line (or in a later file) overrides the file's.
#include <functional>
#include <string>
#include <vector>

namespace quiver::app {

// "" when `name = value` is a valid scenario option, otherwise what is wrong with it.
using ScenarioCheck = std::function<std::string(const std::string& name, const std::string& value)>;

// The file's options as command-line tokens ("--twist=60"), each passed through `check`. Throws
// std::runtime_error naming the file, the line and what is wrong.
std::vector<std::string> parseScenarioFile(const std::string& text, const std::string& fileName, const ScenarioCheck& check);

// Replaces each `--scenario FILE` (or `--scenario=FILE`) in `args` by the file's options, less
// those that a later argument sets again.
std::vector<std::string> expandScenarioFiles(const std::vector<std::string>& args, const ScenarioCheck& check);

} // namespace quiver::app
