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
// `--scenario FILE` stands for those options, at its place on the command line; options given
// after it override the file's (the last value of an option wins).
#include <string>
#include <vector>

namespace quiver::app {

// The file's options as command-line tokens ("--twist=60"). `known` lists the option names a
// scenario may set. Throws std::runtime_error naming the file, the line and what is wrong.
std::vector<std::string> parseScenarioFile(const std::string& text, const std::string& fileName,
                                           const std::vector<std::string>& known);

// Replaces each `--scenario FILE` (or `--scenario=FILE`) in `args` by the file's options.
std::vector<std::string> expandScenarioFiles(const std::vector<std::string>& args, const std::vector<std::string>& known);

} // namespace quiver::app
