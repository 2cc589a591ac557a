#pragma once
// The box [-h, h] (half extents h) as a closed triangle surface: 8 corners (corner k has +h[a] where
// bit a of k is set), two triangles a face, counter-clockwise seen from outside.
#include <vector>

namespace quiver::test {

struct BoxSurface {
  std::vector<double> positions;  // 3 per corner
  std::vector<int> triangles;     // 3 corner indices each
};

inline BoxSurface boxSurface(const double half[3]) {
  BoxSurface s;
  for (int k = 0; k < 8; ++k)
    for (int a = 0; a < 3; ++a) s.positions.push_back(((k >> a) & 1 ? 1 : -1) * half[a]);
  const int quads[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  for (const auto& q : quads) s.triangles.insert(s.triangles.end(), {q[0], q[1], q[2], q[0], q[2], q[3]});
  return s;
}

} // namespace quiver::test
