#pragma once
// Checking an artist's closed triangle surface before it is tetrahedralized: every problem a
// mesher would choke on, or silently mesh wrong, found and counted. Repairs it makes and says:
// degenerate and repeated triangles dropped, inconsistent or inward orientation turned, pieces
// inside the main one set aside (a render mesh carries them; the simulation does not need them).
// Problems it reports with counts and the first place: holes (open edges), edges of more than two
// triangles, triangles that cross each other, pieces apart from the main one, coordinates that
// are not finite or absurdly large.
#include <array>
#include <string>
#include <vector>

namespace quiver {

struct CheckedSurface {
  std::vector<double> positions;              // 3 per vertex, as given (and the centres of closed holes)
  std::vector<std::array<int, 3>> triangles;  // the main piece, consistently outward
  std::vector<std::string> repairs;           // what was changed, one sentence each
  double volume = 0;                          // enclosed by `triangles`
};

struct SurfaceCheckOptions {
  bool fillHoles = false;  // close each hole (a loop of open edges) with a fan around its centre, and say so
};

// Throws MeshError "NAME: ..." naming the problem, its count and the first place.
CheckedSurface checkSurface(const std::vector<double>& positions, const std::vector<int>& triangles, const std::string& name,
                            const SurfaceCheckOptions& options = {});

// Signed volume enclosed by closed, consistently oriented triangles (positive when outward).
double enclosedVolume(const std::vector<double>& positions, const std::vector<std::array<int, 3>>& triangles);

} // namespace quiver
