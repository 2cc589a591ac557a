#include "common/surface.h"

#include <algorithm>
#include <map>

namespace quiver {

std::vector<std::array<int, 3>> boundaryTriangles(const TetMesh& mesh) {
  // For det[X1-X0, X2-X0, X3-X0] > 0 these four faces wind counter-clockwise seen from outside.
  static const int faces[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  std::map<std::array<int, 3>, std::pair<int, std::array<int, 3>>> seen;  // sorted face -> (count, oriented)
  std::vector<std::array<int, 3>> order;
  for (const Tet& t : mesh.tets)
    for (const auto& f : faces) {
      const std::array<int, 3> oriented{t[f[0]], t[f[1]], t[f[2]]};
      std::array<int, 3> key = oriented;
      std::sort(key.begin(), key.end());
      auto [it, fresh] = seen.emplace(key, std::make_pair(0, oriented));
      ++it->second.first;
      if (fresh) order.push_back(key);
    }
  std::vector<std::array<int, 3>> out;
  for (const auto& key : order) {
    const auto& [count, oriented] = seen[key];
    if (count == 1) out.push_back(oriented);
  }
  return out;
}

} // namespace quiver
