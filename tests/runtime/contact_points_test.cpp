// A free model's contact points (contact_points.h): every surface vertex once, levels falling, and
// each level and above spread over the surface as evenly as a grid of its count would be.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <vector>

#include "runtime/src/contact_points.h"

namespace quiver {
namespace {

void* allocate(size_t bytes, size_t alignment, void*) { return std::aligned_alloc(alignment, (bytes + alignment - 1) / alignment * alignment); }
void release(void* p, void*) { std::free(p); }

TEST(ContactPoints, EachLevelAndAboveCoversTheSurfaceEvenly) {
  // A 1 x 0.4 m face, 41 x 17 vertices 2.5 cm apart, and a vertex off the surface (of no triangle).
  const int nx = 41, ny = 17;
  std::vector<double> rest;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) rest.insert(rest.end(), {0.025 * i, 0.025 * j, 0.0});
  rest.insert(rest.end(), {0.5, 0.2, 1.0});
  std::vector<unsigned> triangles;
  for (int j = 0; j + 1 < ny; ++j)
    for (int i = 0; i + 1 < nx; ++i) {
      const unsigned v = unsigned(j * nx + i);
      triangles.insert(triangles.end(), {v, v + 1, v + nx + 1, v, v + nx + 1, v + nx});
    }
  const int n = nx * ny + 1;
  std::vector<int> vertices(n, -1);
  std::vector<unsigned char> levels(n, 0);
  const qv_allocator allocator{allocate, release, nullptr};
  const int count = rt::orderContactPoints(rest.data(), n, triangles.data(), int(triangles.size() / 3), allocator, vertices.data(), levels.data());
  ASSERT_EQ(count, nx * ny);
  std::vector<int> sorted(vertices.begin(), vertices.begin() + count);
  std::sort(sorted.begin(), sorted.end());
  for (int k = 0; k < count; ++k) ASSERT_EQ(sorted[k], k);  // each face vertex once, not the loose one
  for (int k = 1; k < count; ++k) ASSERT_LE(levels[k], levels[k - 1]);
  // Each level and above: the farthest any face vertex is from one of them, against the spacing of
  // a square grid of as many points over the face. A random subset of the same size leaves holes
  // 1.4-3 times wider (checked below).
  const auto coverage = [&](const std::vector<int>& kept) {
    double farthest = 0;
    for (int v = 0; v < count; ++v) {
      double nearest = INFINITY;
      for (const int w : kept) nearest = std::min(nearest, std::hypot(rest[3 * v] - rest[3 * w], rest[3 * v + 1] - rest[3 * w + 1]));
      farthest = std::max(farthest, nearest);
    }
    return farthest;
  };
  std::srand(7);
  for (int level = 1; level <= levels[0]; ++level) {
    std::vector<int> kept, random;
    for (int k = 0; k < count && levels[k] >= level; ++k) kept.push_back(vertices[k]);
    if (kept.size() < 4) break;
    if (2 * kept.size() > size_t(count)) continue;  // not yet thinned
    std::vector<int> all(sorted);
    for (size_t k = 0; k < kept.size(); ++k) {
      std::swap(all[k], all[k + size_t(std::rand()) % (all.size() - k)]);
      random.push_back(all[k]);
    }
    const double spacing = std::sqrt(1.0 * 0.4 / double(kept.size())), spread = coverage(kept), scattered = coverage(random);
    std::printf("level >= %d: %zu vertices, every face vertex within %.3g m of one (grid spacing %.3g m; a random %zu: %.3g m)\n",
                level, kept.size(), spread, spacing, kept.size(), scattered);
    EXPECT_LE(spread, 1.25 * spacing);
    EXPECT_GT(scattered, 1.3 * spread);
  }
}

} // namespace
} // namespace quiver
