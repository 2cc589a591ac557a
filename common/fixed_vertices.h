#pragma once
// Which vertices are fixed (Dirichlet): geometric selectors and lists of vertex numbers, combined
// as a union. Numbers refer to the mesh file's vertex order and are mapped onto the loaded mesh
// (whose unreferenced vertices may have been dropped). Reading a list from a file (Vega .bou)
// is formats/'s: formats/mesh/read_mesh.h.
#include <cstdint>
#include <string>
#include <vector>

#include "common/mesh_checks.h"

namespace quiver {

// Vertex numbers from one source, 0-based in the file's vertex order. `source` names it in
// messages ("--fix-indices", "beam.bou"); `firstNumber` is how the source counts (0, or 1 for
// .bou files), so that messages quote its own numbers.
struct FileVertexList {
  std::string source;
  std::vector<int64_t> indices;
  int firstNumber = 0;
};

struct FixedVertexRequest {
  std::vector<std::string> selectors;  // VertexSelector expressions, e.g. "x<0.01"
  std::vector<FileVertexList> lists;

  bool empty() const { return selectors.empty() && lists.empty(); }
};

// Loaded-vertex indices, ascending and unique. Throws MeshError when a selector is malformed, a
// number is out of range or names a dropped vertex, or any one source selects no vertex at all.
std::vector<int> selectFixedVertices(const CheckedMesh& mesh, const FixedVertexRequest& request);

} // namespace quiver
