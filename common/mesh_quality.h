#pragma once
// Element quality figures, for `quiver-mesh info` and for warning about meshes that will make
// stiff or ill-conditioned systems.
#include "common/tet_mesh.h"

namespace quiver {

struct Range {
  double min = 0, mean = 0, max = 0;
};

struct MeshQuality {
  Range normalisedVolume;  // 6*sqrt(2)*V / l_rms^3: 1 for a regular tet, -> 0 for slivers
  Range dihedralDegrees;   // over all six dihedral angles of every tet (regular: 70.53)
  Range edgeLength;        // over every tet edge (shared edges counted once per tet)
  Range tetVolume;         // signed volumes
};

// Requires a non-empty mesh.
MeshQuality measureQuality(const TetMesh& mesh);

} // namespace quiver
