#include "apps/support/mesh_options.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <iostream>
#include <sstream>

#include "common/mesh_error.h"
#include "formats/mesh/read_mesh.h"
#include "formats/mesh/text_cursor.h"
#include "formats/model/qvr.h"

namespace quiver::app {

void MeshOptions::addTo(CLI::App& app, const std::string& meshHelp) {
  app.add_option("mesh", path, meshHelp)->required();
  app.add_flag("--fix-orientation", checks.fixOrientation,
               "Flip inverted tets (with a warning) instead of refusing the mesh");
  app.add_option("--degenerate-tolerance", checks.degenerateTolerance,
                 "Refuse tets whose normalised volume 6*sqrt(2)*V/l_rms^3 (1 = regular tet) is below this")
      ->capture_default_str()
      ->check(Between(0.0, 1.0));
}

CheckedMesh MeshOptions::load(const std::string& tool) const {
  CheckedMesh mesh = loadMesh(path, checks);
  if (!tool.empty())
    for (const std::string& w : mesh.warnings) std::cerr << tool << ": warning: " << w << "\n";
  return mesh;
}

void FixedVertexOptions::addTo(CLI::App& app) {
  app.add_option("--fix", selectors,
                 "Fix the vertices an expression selects, in mesh units: \"x<0.01\", \"y>=max-1e-3 & z<0.5\", "
                 "\"box:x0,y0,z0,x1,y1,z1\" (repeatable; union)");
  app.add_option("--fix-indices", indexList, "Fix vertices by 0-based number in the file's order: \"0,5,10-20\"");
  app.add_option("--bou", bouFiles, "Fix the vertices listed in a Vega .bou file (1-based; repeatable)")
      ->check(CLI::ExistingFile);
}

FixedVertexRequest FixedVertexOptions::resolved() const {
  FixedVertexRequest r;
  r.selectors = selectors;
  if (!indexList.empty()) r.lists.push_back({"--fix-indices", parseIndexList(indexList, "--fix-indices"), 0});
  for (const std::string& bou : bouFiles) r.lists.push_back(readBouFile(bou));
  return r;
}

std::vector<int64_t> parseIndexList(const std::string& text, const std::string& what) {
  std::vector<int64_t> out;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    size_t dash = item.find('-', 1);
    int64_t lo, hi;
    bool ok = dash == std::string::npos ? parseInteger(item, lo) && (hi = lo, true)
                                        : parseInteger(item.substr(0, dash), lo) && parseInteger(item.substr(dash + 1), hi);
    if (!ok || lo < 0 || hi < lo || hi - lo > 100000000)
      throw MeshError(what + ": '" + item + "' is not a vertex index or range like 10-12 (0-based)");
    for (int64_t i = lo; i <= hi; ++i) out.push_back(i);
  }
  if (out.empty()) throw MeshError(what + ": empty index list");
  return out;
}

std::vector<int> FixedVertexOptions::select(const CheckedMesh& mesh) const { return selectFixedVertices(mesh, resolved()); }

bool parseNumber(const std::string& text, double& value) {
  size_t used = 0;
  try {
    value = std::stod(text, &used);
  } catch (const std::exception&) {
    return false;
  }
  return used == text.size();
}

namespace {

CLI::Validator numberWhere(std::function<bool(double)> holds, const std::string& expected, const std::string& name) {
  return CLI::Validator(
      [holds, expected](std::string& text) -> std::string {
        double value = 0;
        return parseNumber(text, value) && holds(value) ? "" : "expected " + expected + ", not '" + text + "'";
      },
      name);
}

} // namespace

const CLI::Validator Positive = numberWhere([](double x) { return x > 0 && std::isfinite(x); }, "a positive number", "POSITIVE");
const CLI::Validator NonNegative =
    numberWhere([](double x) { return x >= 0 && std::isfinite(x); }, "a number >= 0", "NON-NEGATIVE");
const CLI::Validator TimeStep = numberWhere([](double x) { return x >= kSmallestTimeStep && std::isfinite(x); },
                                            "a time step of at least 1e-12 s", "SECONDS");
const CLI::Validator Finite = numberWhere([](double x) { return std::isfinite(x); }, "a finite number", "FINITE");

CLI::Validator Between(double low, double high) {
  std::ostringstream range;
  range << low << " to " << high;
  return numberWhere([low, high](double x) { return x >= low && x <= high; }, "a number from " + range.str(),
                     "FLOAT in [" + range.str() + "]");
}

CLI::Validator OutputName(std::vector<std::string> extensions) {
  return CLI::Validator(
      [extensions](std::string& name) {
        for (const std::string& e : extensions)
          if (name.size() > e.size() && name.compare(name.size() - e.size(), e.size(), e) == 0) {
            name.resize(name.size() - e.size());
            break;
          }
        return std::string();
      },
      "NAME");
}

int runTool(const std::string& tool, CLI::App& app, int argc, char** argv, const std::function<int()>& body,
            const ArgumentRewrite& rewrite) {
  std::vector<std::string> args(argv + 1, argv + argc);
  try {
    if (rewrite) args = rewrite(args);
  } catch (const std::exception& e) {
    std::cerr << tool << ": error: " << e.what() << "\n";
    return 1;
  }
  std::reverse(args.begin(), args.end());  // CLI11 takes them last first
  if (app.get_name().empty()) app.name(tool);
  try {
    app.parse(args);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  try {
    return body();
  } catch (const std::exception& e) {
    std::cerr << tool << ": error: " << e.what() << "\n";
    return 1;
  }
}

} // namespace quiver::app
