#pragma once
// Binding points (a render mesh's vertices) to a tet mesh: each point to the tet that contains it,
// with its barycentric weights, so that it moves as the tet's vertices do (Vega's
// generateInterpolant, PhysX's embedded render meshes). A point slightly outside every tet (a fine
// artist's surface over a coarser tet mesh) goes with the nearest tet within a tolerance.
#include <array>
#include <string>
#include <vector>

#include "common/tet_mesh.h"

namespace quiver {

struct Embedding {
  std::vector<int> tet;                      // per point
  std::vector<std::array<double, 4>> weights; // per point, on the tet's vertices in order; sum 1
  int outside = 0;                           // points bound to a nearest tet
  double farthest = 0;                       // the largest distance of such a point to its tet, m
};

// Points 3 per point. Outside points within `tolerance` of a tet take the barycentric weights of
// their own position (extrapolated; Σ w X reproduces the point) when every weight is in [-0.5, 1.5],
// else those of the closest point of the tet. Throws MeshError naming the first point farther
// ("NAME: point i (x, y, z) is D m from the nearest tet, beyond the tolerance T m").
Embedding embedPoints(const TetMesh& mesh, const std::vector<double>& points, double tolerance, const std::string& name);

} // namespace quiver
