#pragma once
// Structured tetrahedral meshes of a box, for the demo, the tests and the benchmarks.
#include <array>

#include "common/tet_mesh.h"

namespace quiver {

// The box [0, size.x] x [0, size.y] x [0, size.z] cut into cells[0] x cells[1] x cells[2] cells,
// each split into six positively oriented tets around its (0,0,0)-(1,1,1) diagonal (Kuhn
// subdivision: faces of neighbouring cells match, so the mesh is conforming). Vertices are
// numbered x fastest, then y, then z. Requires size > 0 and cells >= 1 in each direction.
TetMesh makeBoxMesh(const Eigen::Vector3d& size, const std::array<int, 3>& cells);

} // namespace quiver
