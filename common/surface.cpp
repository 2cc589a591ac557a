#include "common/surface.h"

#include <algorithm>
#include <cstdint>
#include <utility>

namespace quiver {

namespace {

// For det[X1-X0, X2-X0, X3-X0] > 0 these four faces wind counter-clockwise seen from outside.
const int kFaces[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};

} // namespace

std::vector<std::pair<std::array<int, 3>, int64_t>> sortedFaces(const TetMesh& mesh) {
  // A sort, not a map: 4 faces a tet on meshes of 100k tets and more.
  std::vector<std::pair<std::array<int, 3>, int64_t>> keyed;
  keyed.reserve(4 * mesh.tets.size());
  for (size_t t = 0; t < mesh.tets.size(); ++t)
    for (int f = 0; f < 4; ++f) {
      std::array<int, 3> key{mesh.tets[t][kFaces[f][0]], mesh.tets[t][kFaces[f][1]], mesh.tets[t][kFaces[f][2]]};
      std::sort(key.begin(), key.end());
      keyed.emplace_back(key, static_cast<int64_t>(4 * t + f));
    }
  std::sort(keyed.begin(), keyed.end());
  return keyed;
}

std::vector<std::array<int, 3>> boundaryTriangles(const TetMesh& mesh) {
  const std::vector<std::pair<std::array<int, 3>, int64_t>> keyed = sortedFaces(mesh);
  std::vector<int64_t> once;  // faces of one tet only, in the order the tets list them
  for (size_t i = 0; i < keyed.size();) {
    size_t j = i + 1;
    while (j < keyed.size() && keyed[j].first == keyed[i].first) ++j;
    if (j == i + 1) once.push_back(keyed[i].second);
    i = j;
  }
  std::sort(once.begin(), once.end());
  std::vector<std::array<int, 3>> out;
  out.reserve(once.size());
  for (int64_t where : once) {
    const Tet& t = mesh.tets[where / 4];
    const int* f = kFaces[where % 4];
    out.push_back({t[f[0]], t[f[1]], t[f[2]]});
  }
  return out;
}

} // namespace quiver
