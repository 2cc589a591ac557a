// Binding points to tets (common/embedding.h): points inside get weights that reproduce them and
// lie in their tet; points slightly outside go with the nearest tet; farther ones are named.
#include <gtest/gtest.h>

#include <random>
#include <string>

#include "common/box_mesh.h"
#include "common/embedding.h"
#include "common/mesh_error.h"

namespace quiver {
namespace {

TEST(Embedding, PointsInsideAreReproducedByTheirTet) {
  const TetMesh mesh = makeBoxMesh({1.0, 0.5, 0.25}, {8, 4, 2});
  std::mt19937 random(3);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<double> points;
  for (int i = 0; i < 500; ++i) points.insert(points.end(), {u(random), 0.5 * u(random), 0.25 * u(random)});
  points.insert(points.end(), {0, 0, 0, 1, 0.5, 0.25, 0.5, 0.25, 0.125});  // corners and a shared vertex
  const Embedding e = embedPoints(mesh, points, 1e-3, "render.obj");
  EXPECT_EQ(e.outside, 0);
  for (size_t i = 0; i < points.size() / 3; ++i) {
    Eigen::Vector3d x = Eigen::Vector3d::Zero();
    double sum = 0;
    for (int k = 0; k < 4; ++k) {
      x += e.weights[i][k] * mesh.vertices[mesh.tets[e.tet[i]][k]];
      sum += e.weights[i][k];
      EXPECT_GE(e.weights[i][k], -1e-12);
    }
    EXPECT_NEAR(sum, 1, 1e-12);
    EXPECT_LT((x - Eigen::Vector3d(points[3 * i], points[3 * i + 1], points[3 * i + 2])).norm(), 1e-12);
  }
}

TEST(Embedding, PointsOutsideGoWithTheNearestTetWithinTheTolerance) {
  const TetMesh mesh = makeBoxMesh({1.0, 1.0, 1.0}, {2, 2, 2});
  // 1 cm above the top face, and 1 cm beyond a corner: extrapolated weights still reproduce them.
  const std::vector<double> points{0.3, 0.6, 1.01, 1.01, 1.01, 1.01};
  const Embedding e = embedPoints(mesh, points, 0.05, "render.obj");
  EXPECT_EQ(e.outside, 2);
  EXPECT_NEAR(e.farthest, 0.01 * std::sqrt(3.0), 1e-12);
  for (size_t i = 0; i < 2; ++i) {
    Eigen::Vector3d x = Eigen::Vector3d::Zero();
    for (int k = 0; k < 4; ++k) x += e.weights[i][k] * mesh.vertices[mesh.tets[e.tet[i]][k]];
    EXPECT_LT((x - Eigen::Vector3d(&points[3 * i])).norm(), 1e-12);
  }
  try {
    embedPoints(mesh, {0.5, 0.5, 1.2}, 0.05, "render.obj");  // 0.2 m above: no tet's box within reach
    ADD_FAILURE() << "a point 0.2 m away was bound";
  } catch (const MeshError& error) {
    EXPECT_EQ(std::string(error.what()), "render.obj: point 0 (0.5, 0.5, 1.2) is more than the tolerance 0.05 m from every tet");
  }
}

} // namespace
} // namespace quiver
