#include "formats/mesh/fixed_vertices.h"

#include <algorithm>
#include <sstream>
#include <stdexcept>

#include "common/vertex_selector.h"
#include "formats/mesh/mesh_error.h"
#include "formats/mesh/text_cursor.h"

namespace quiver {

namespace {

std::string axisRanges(const TetMesh& mesh) {
  auto box = boundingBox(mesh);
  std::ostringstream s;
  s.precision(6);
  s << "the mesh spans x [" << box[0].x() << ", " << box[1].x() << "], y [" << box[0].y() << ", " << box[1].y()
    << "], z [" << box[0].z() << ", " << box[1].z() << "]";
  return s.str();
}

} // namespace

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

std::vector<int> selectFixedVertices(const CheckedMesh& mesh, const FixedVertexRequest& request) {
  std::vector<int> fixed;
  for (const std::string& expr : request.selectors) {
    std::vector<int> chosen;
    try {
      chosen = VertexSelector(expr).select(mesh.mesh);
    } catch (const std::invalid_argument& e) {
      throw MeshError(e.what());
    }
    if (chosen.empty()) throw MeshError("vertex selector '" + expr + "' selects no vertex; " + axisRanges(mesh.mesh));
    fixed.insert(fixed.end(), chosen.begin(), chosen.end());
  }
  auto mapFileVertex = [&](int64_t fileIndex, const std::string& source) {
    if (fileIndex < 0 || fileIndex >= static_cast<int64_t>(mesh.loadedVertex.size()))
      throw MeshError(source + ": vertex " + std::to_string(fileIndex) + " is out of range [0, " +
                      std::to_string(mesh.loadedVertex.size()) + ")");
    int v = mesh.loadedVertex[fileIndex];
    if (v < 0) throw MeshError(source + ": vertex " + std::to_string(fileIndex) + " (0-based) belongs to no tet and was dropped");
    fixed.push_back(v);
  };
  for (int64_t i : request.indices) mapFileVertex(i, "fixed vertex index");
  for (const std::string& bou : request.bouFiles) {
    std::vector<int> listed = parseBou(readFileBytes(bou), bou, static_cast<int>(mesh.loadedVertex.size()));
    if (listed.empty()) throw MeshError(bou + ": lists no vertex");
    for (int v : listed) mapFileVertex(v, bou);
  }
  std::sort(fixed.begin(), fixed.end());
  fixed.erase(std::unique(fixed.begin(), fixed.end()), fixed.end());
  return fixed;
}

} // namespace quiver
