// The broad phase against testing every pair: each pair of balls that touch (centres closer than
// the sum of their radii, the half widths) is among its overlaps, each overlap comes once, and the
// lists per body hold the same pairs in ascending order; when they do not fit it says so.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>
#include <utility>
#include <vector>

#include "runtime/src/broad_phase.h"

namespace quiver::rt {
namespace {

struct Scene {
  std::vector<char> block;
  BroadPhase broad;
  explicit Scene(int bodies) {
    BlockCarver measure(nullptr);
    broad.carve(measure, bodies);
    block.resize(measure.size() + 64);
    char* base = block.data() + (64 - reinterpret_cast<uintptr_t>(block.data()) % 64) % 64;
    BlockCarver place(base);
    broad.carve(place, bodies);
  }
};

std::set<std::pair<int, int>> overlaps(const BroadPhase& b) {
  std::set<std::pair<int, int>> out;
  forEachOverlap(b, [&](int i, int j) {
    EXPECT_NE(i, j);
    EXPECT_TRUE(out.insert({std::min(i, j), std::max(i, j)}).second) << "pair " << i << ", " << j << " twice";
  });
  return out;
}

TEST(BroadPhase, EveryPairOfTouchingBallsIsAnOverlapOnceAndTheListsAgree) {
  std::mt19937 rng(3);
  for (const double extent : {1.0, 10.0, 100.0}) {  // crowded to sparse
    const int n = 400;
    Scene scene(n);
    BroadPhase& b = scene.broad;
    std::uniform_real_distribution<double> where(-extent, extent), size(0.05, 1.0);
    for (int i = 0; i < n; ++i) {
      for (int a = 0; a < 3; ++a) b.centres[3 * i + a] = where(rng) * (a == 1 ? 0.3 : 1);  // spread least along y
      b.halfWidth[i] = size(rng);
    }
    sortIntervals(b, n);
    const std::set<std::pair<int, int>> found = overlaps(b);
    int touching = 0;
    for (int i = 0; i < n; ++i)
      for (int j = i + 1; j < n; ++j) {
        const double d = std::hypot(b.centres[3 * i] - b.centres[3 * j], b.centres[3 * i + 1] - b.centres[3 * j + 1],
                                    b.centres[3 * i + 2] - b.centres[3 * j + 2]);
        if (d > b.halfWidth[i] + b.halfWidth[j]) continue;
        ++touching;
        EXPECT_TRUE(found.count({i, j})) << "touching balls " << i << " and " << j << " missed";
      }
    listOverlaps(b);
    std::printf("%d balls in a box of half size %g: %d pairs touch, %zu overlaps of %d pairs; lists %s\n", n, extent,
                touching, found.size(), n * (n - 1) / 2, b.rowsValid ? "fit" : "do not fit");
    if (extent > 1) {
      EXPECT_LT(found.size(), static_cast<size_t>(n * (n - 1) / 8));  // far fewer than all pairs
    }
    ASSERT_EQ(b.rowsValid, 2 * found.size() <= static_cast<size_t>(b.neighbourCapacity));
    if (!b.rowsValid) continue;
    size_t listed = 0;
    for (int i = 0; i < n; ++i) {
      const int* row = b.neighbours + b.rowStart[i];
      const int length = b.rowStart[i + 1] - b.rowStart[i];
      EXPECT_TRUE(std::is_sorted(row, row + length)) << "row " << i;
      for (int k = 0; k < length; ++k) EXPECT_TRUE(found.count({std::min(i, row[k]), std::max(i, row[k])}));
      listed += static_cast<size_t>(length);
    }
    EXPECT_EQ(listed, 2 * found.size());
  }
}

TEST(BroadPhase, ListsThatDoNotFitAreRefused) {
  const int n = 2 * BroadPhase::kNeighboursPerBody + 2;  // all at one point: n - 1 overlaps each
  Scene scene(n);
  BroadPhase& b = scene.broad;
  for (int i = 0; i < n; ++i) {
    for (int a = 0; a < 3; ++a) b.centres[3 * i + a] = 0;
    b.halfWidth[i] = 1;
  }
  sortIntervals(b, n);
  EXPECT_EQ(overlaps(b).size(), static_cast<size_t>(n * (n - 1) / 2));
  listOverlaps(b);
  EXPECT_FALSE(b.rowsValid);
}

} // namespace
} // namespace quiver::rt
