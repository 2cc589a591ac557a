#pragma once
// The boundary surface of a tet mesh, for rendering and for surface integrals.
#include <array>
#include <vector>

#include "common/tet_mesh.h"

namespace quiver {

// Faces that belong to exactly one tet, as vertex triples ordered counter-clockwise seen from
// outside (for positively oriented tets), in tet order. A closed mesh gives a closed surface.
std::vector<std::array<int, 3>> boundaryTriangles(const TetMesh& mesh);

} // namespace quiver
