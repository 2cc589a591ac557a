#pragma once
// Which vertices are fixed (Dirichlet): from geometric selectors, explicit indices and Vega .bou
// files, combined as a union. Indices and .bou numbers refer to the file's vertex order and are
// mapped onto the loaded mesh (whose unreferenced vertices may have been dropped).
#include <cstdint>
#include <string>
#include <vector>

#include "formats/mesh/mesh_checks.h"

namespace quiver {

struct FixedVertexRequest {
  std::vector<std::string> selectors;  // VertexSelector expressions, e.g. "x<0.01"
  std::vector<int64_t> indices;        // 0-based vertex numbers in the file's vertex order
  std::vector<std::string> bouFiles;   // Vega .bou files (1-based numbers, file vertex order)

  bool empty() const { return selectors.empty() && indices.empty() && bouFiles.empty(); }
};

// Loaded-vertex indices, ascending and unique. Throws MeshError when a selector is malformed, an
// index is out of range or names a dropped vertex, or any one source selects no vertex at all.
std::vector<int> selectFixedVertices(const CheckedMesh& mesh, const FixedVertexRequest& request);

// Parses "3,7,10-12" (0-based, ranges inclusive) into indices; throws MeshError naming `what`.
std::vector<int64_t> parseIndexList(const std::string& text, const std::string& what);

} // namespace quiver
