#include "contact_points.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace quiver::rt {

namespace {

struct Candidate {
  uint64_t cell;
  double offCentre;  // squared distance to the cell's centre
  int vertex;
};

} // namespace

int orderContactPoints(const double* rest, int vertexCount, const unsigned* triangles, int triangleCount,
                       const qv_allocator& allocator, int* vertices, unsigned char* levels) {
  const size_t n = static_cast<size_t>(vertexCount);
  auto* candidates = static_cast<Candidate*>(allocator.allocate(n * sizeof(Candidate) + n, 64, allocator.user));
  if (!candidates) return -1;
  unsigned char* level = reinterpret_cast<unsigned char*>(candidates + n);  // by vertex
  std::fill(level, level + n, 0);
  for (size_t k = 0; k < 3 * static_cast<size_t>(triangleCount); ++k) level[triangles[k]] = 1;
  int count = 0;
  double low[3] = {INFINITY, INFINITY, INFINITY}, high[3] = {-INFINITY, -INFINITY, -INFINITY}, edges = 0;
  for (int v = 0; v < vertexCount; ++v) {
    if (!level[v]) continue;
    level[v] = 0;
    vertices[count++] = v;
    for (int a = 0; a < 3; ++a) low[a] = std::fmin(low[a], rest[3 * v + a]), high[a] = std::fmax(high[a], rest[3 * v + a]);
  }
  for (int t = 0; t < triangleCount; ++t)
    for (int k = 0; k < 3; ++k) {
      const unsigned i = triangles[3 * t + k], j = triangles[3 * t + (k + 1) % 3];
      edges += std::sqrt(std::pow(rest[3 * i] - rest[3 * j], 2) + std::pow(rest[3 * i + 1] - rest[3 * j + 1], 2) +
                         std::pow(rest[3 * i + 2] - rest[3 * j + 2], 2));
    }
  const double size = std::fmax(high[0] - low[0], std::fmax(high[1] - low[1], high[2] - low[2]));
  const double edge = triangleCount ? edges / (3.0 * triangleCount) : size;
  // From cells about an edge long (2^finest across the model) to one cell; each pass keeps one per cell.
  const int finest = size > 0 && edge > 0 ? std::clamp(static_cast<int>(std::ceil(std::log2(size / edge))), 0, 20) : 0;
  int alive = count;
  for (int k = 0; k < count; ++k) candidates[k].vertex = vertices[k];
  for (int grid = finest; grid >= 0 && alive > 1; --grid) {
    const double cell = size / std::ldexp(1.0, grid);
    const uint64_t cellsPerAxis = uint64_t(1) << grid;
    for (int k = 0; k < alive; ++k) {
      Candidate& c = candidates[k];
      uint64_t key = 0;
      c.offCentre = 0;
      for (int a = 0; a < 3; ++a) {
        const double x = (rest[3 * c.vertex + a] - low[a]) / cell;
        const uint64_t i = std::min(static_cast<uint64_t>(std::fmax(x, 0.0)), cellsPerAxis - 1);
        key = (key << 21) | i;
        c.offCentre += (x - (i + 0.5)) * (x - (i + 0.5));
      }
      c.cell = key;
    }
    std::sort(candidates, candidates + alive, [](const Candidate& x, const Candidate& y) {
      if (x.cell != y.cell) return x.cell < y.cell;
      if (x.offCentre != y.offCentre) return x.offCentre < y.offCentre;
      return x.vertex < y.vertex;
    });
    int kept = 0;
    for (int k = 0; k < alive; ++k)
      if (k == 0 || candidates[k].cell != candidates[k - 1].cell) {
        const int v = candidates[k].vertex;
        level[v] = static_cast<unsigned char>(std::min(level[v] + 1, kContactLevels - 1));
        candidates[kept++] = candidates[k];
      }
    alive = kept;
  }
  std::sort(vertices, vertices + count, [&](int x, int y) { return level[x] != level[y] ? level[x] > level[y] : x < y; });
  for (int k = 0; k < count; ++k) levels[k] = level[vertices[k]];
  allocator.release(candidates, allocator.user);
  return count;
}

} // namespace quiver::rt
