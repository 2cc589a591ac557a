#include "common/fixed_vertices.h"

#include <algorithm>
#include <sstream>
#include <stdexcept>

#include "common/vertex_selector.h"
#include "common/mesh_error.h"

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
  const int64_t count = static_cast<int64_t>(mesh.loadedVertex.size());
  for (const FileVertexList& list : request.lists) {
    if (list.indices.empty()) throw MeshError(list.source + ": lists no vertex");
    for (int64_t fileIndex : list.indices) {
      const std::string number = std::to_string(fileIndex + list.firstNumber);
      if (fileIndex < 0 || fileIndex >= count)
        throw MeshError(list.source + ": vertex " + number + " is out of range [" + std::to_string(list.firstNumber) +
                        ", " + std::to_string(count - 1 + list.firstNumber) + "]" +
                        (list.firstNumber ? " (numbered from " + std::to_string(list.firstNumber) + ")" : ""));
      const int v = mesh.loadedVertex[fileIndex];
      if (v < 0) throw MeshError(list.source + ": vertex " + number + " belongs to no tet and was dropped");
      fixed.push_back(v);
    }
  }
  std::sort(fixed.begin(), fixed.end());
  fixed.erase(std::unique(fixed.begin(), fixed.end()), fixed.end());
  return fixed;
}

} // namespace quiver
