#pragma once
// Command-line options shared by the tools that read a mesh, so that every tool spells and
// documents them the same way.
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "common/fixed_vertices.h"
#include "common/mesh_checks.h"

namespace quiver::app {

struct MeshOptions {
  std::string path;
  MeshCheckOptions checks;

  // Adds MESH (positional) and --fix-orientation / --degenerate-tolerance.
  void addTo(CLI::App& app, const std::string& meshHelp = "Tetrahedral mesh (.msh .vtk .vtu .mesh .veg .node/.ele)");
  // Loads and validates the mesh, printing warnings to stderr as "TOOL: warning: ..." (none when TOOL is "").
  CheckedMesh load(const std::string& tool) const;
};

struct FixedVertexOptions {
  std::vector<std::string> selectors;
  std::string indexList;
  std::vector<std::string> bouFiles;

  // Adds --fix EXPR (repeatable), --fix-indices LIST and --bou FILE (repeatable).
  void addTo(CLI::App& app);
  bool given() const { return !selectors.empty() || !indexList.empty() || !bouFiles.empty(); }
  // The request with --fix-indices parsed and the .bou files read; throws naming --fix-indices or
  // the file and line of what is malformed.
  FixedVertexRequest resolved() const;
  std::vector<int> select(const CheckedMesh& mesh) const;
};

// Parses "3,7,10-12" (0-based, ranges inclusive) into indices; throws MeshError naming `what`.
std::vector<int64_t> parseIndexList(const std::string& text, const std::string& what);

// All of `text` as a number (std::stod's syntax); false when it is not one or something follows it.
bool parseNumber(const std::string& text, double& value);

// A finite number above zero, or at least zero. CLI::PositiveNumber says "Value abc not in range 0
// to 1.79e308" of a word, and prints that bound in full; these say what is expected.
extern const CLI::Validator Positive;
extern const CLI::Validator NonNegative;
// A time step in s, at least kSmallestTimeStep (formats/model/qvr.h), finite.
extern const CLI::Validator TimeStep;
// Any finite number (a vector option checks each of its values).
extern const CLI::Validator Finite;
// A number from `low` to `high`: CLI::Range lets NaN through (no comparison with it fails).
CLI::Validator Between(double low, double high);

// An output NAME the tool extends itself (NAME.qvr, NAME.h5, ...): drops one of `extensions` the
// user gave, so that "-o model.qvr" writes model.qvr, not model.qvr.qvr.
CLI::Validator OutputName(std::vector<std::string> extensions);

// Rewrites the command line (without the program name) before it is parsed; may throw.
using ArgumentRewrite = std::function<std::vector<std::string>(const std::vector<std::string>&)>;

// Parses the command line (after `rewrite`, if given) and runs `body`, turning any exception into
// "TOOL: error: message" on stderr and exit code 1.
int runTool(const std::string& tool, CLI::App& app, int argc, char** argv, const std::function<int()>& body,
            const ArgumentRewrite& rewrite = {});

} // namespace quiver::app
