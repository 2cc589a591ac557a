#pragma once
// The boundary surface of a tet mesh, for rendering and for surface integrals.
#include <array>
#include <cstdint>
#include <utility>
#include <vector>

#include "common/tet_mesh.h"

namespace quiver {

// Every tet's four faces, each as its vertices sorted and where it appears (4 t + f), sorted: a face
// tets share lies next to its twins.
std::vector<std::pair<std::array<int, 3>, int64_t>> sortedFaces(const TetMesh& mesh);

// Faces that belong to exactly one tet, as vertex triples ordered counter-clockwise seen from
// outside (for positively oriented tets), in tet order. A closed mesh gives a closed surface.
std::vector<std::array<int, 3>> boundaryTriangles(const TetMesh& mesh);

} // namespace quiver
