#include "apps/view/surface_pick.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace quiver::app {
namespace {

// Two unit squares (two triangles each) facing z, one at z = 0 and one at z = 1.
const std::vector<float> kPositions{0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1};
const std::vector<unsigned> kTriangles{0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 7};

TEST(SurfacePick, TheNearestOfStackedSurfacesFromEitherSide) {
  const Ray down{{0.2, 0.3, 5}, {0, 0, -1}};
  const auto top = pickSurface(down, kPositions, kTriangles);
  ASSERT_TRUE(top);
  EXPECT_GE(top->triangle, 2);
  EXPECT_NEAR(top->distance, 4, 1e-12);
  EXPECT_LT((top->point - Eigen::Vector3d(0.2, 0.3, 1)).norm(), 1e-12);
  EXPECT_EQ(top->vertex, 4) << "(0, 0, 1) is the hit triangle's nearest corner";
  const Ray up{{0.9, 0.8, -5}, {0, 0, 1}};
  const auto bottom = pickSurface(up, kPositions, kTriangles);
  ASSERT_TRUE(bottom);
  EXPECT_LT(bottom->triangle, 2);
  EXPECT_EQ(bottom->vertex, 2);
}

TEST(SurfacePick, MissesOutsideBehindAndThroughNaN) {
  EXPECT_FALSE(pickSurface({{1.5, 0.5, 5}, {0, 0, -1}}, kPositions, kTriangles));
  EXPECT_FALSE(pickSurface({{0.5, 0.5, 5}, {0, 0, 1}}, kPositions, kTriangles)) << "the surfaces are behind the ray";
  std::vector<float> broken = kPositions;
  for (int c = 12; c < 24; ++c) broken[c] = std::numeric_limits<float>::quiet_NaN();
  const auto hit = pickSurface({{0.5, 0.5, 5}, {0, 0, -1}}, broken, kTriangles);
  ASSERT_TRUE(hit) << "the intact square is still found";
  EXPECT_NEAR(hit->point.z(), 0, 1e-12);
}

TEST(SurfacePick, OnAnEdgeAndAtACorner) {
  const auto edge = pickSurface({{0.5, 0.5, 5}, {0, 0, -1}}, kPositions, kTriangles);  // the shared diagonal
  ASSERT_TRUE(edge);
  EXPECT_NEAR(edge->point.z(), 1, 1e-12);
  EXPECT_TRUE(pickSurface({{1, 1, 5}, {0, 0, -1}}, kPositions, kTriangles));
}

TEST(SurfacePick, PlaneCrossing) {
  const Ray ray{{0, 0, 0}, Eigen::Vector3d(1, 1, 0).normalized()};
  const auto at = intersectPlane(ray, {2, 0, 0}, {1, 0, 0});
  ASSERT_TRUE(at);
  EXPECT_LT((*at - Eigen::Vector3d(2, 2, 0)).norm(), 1e-12);
  EXPECT_FALSE(intersectPlane(ray, {0, 0, 1}, {0, 0, 1})) << "parallel";
  EXPECT_FALSE(intersectPlane(ray, {-2, 0, 0}, {1, 0, 0})) << "behind";
}

} // namespace
} // namespace quiver::app
