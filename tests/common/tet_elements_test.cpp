// Shape-function gradients and volumes of single tets, checked against properties every linear
// tet must have and against a tet whose gradients are known in closed form.
#include "common/tet_elements.h"

#include <array>
#include <cmath>
#include <random>
#include <stdexcept>
#include <utility>

#include <Eigen/LU>
#include <gtest/gtest.h>

namespace quiver {
namespace {

TetMesh singleTet(const std::array<Eigen::Vector3d, 4>& x) {
  TetMesh mesh;
  mesh.vertices.assign(x.begin(), x.end());
  mesh.tets.push_back({0, 1, 2, 3});
  return mesh;
}

TetMesh randomTet(std::mt19937& rng) {
  std::uniform_real_distribution<double> coord(-1.0, 1.0);
  std::array<Eigen::Vector3d, 4> x;
  for (auto& p : x) p = Eigen::Vector3d(coord(rng), coord(rng), coord(rng));
  return singleTet(x);
}

TEST(TetElements, RightAngleTetMatchesClosedForm) {
  // Vertices 0, a e_x, b e_y, c e_z: V = abc/6, N_1 = x/a, N_2 = y/b, N_3 = z/c, N_0 = 1 - the rest.
  const double a = 0.5, b = 2.0, c = 3.0;
  const TetElements el = computeTetElements(
      singleTet({Eigen::Vector3d::Zero(), Eigen::Vector3d(a, 0, 0), Eigen::Vector3d(0, b, 0), Eigen::Vector3d(0, 0, c)}));
  ASSERT_EQ(el.count(), 1);
  EXPECT_NEAR(el.volume[0], a * b * c / 6, 1e-15);
  Matrix34 expected;
  expected << -1 / a, 1 / a, 0, 0, //
      -1 / b, 0, 1 / b, 0,         //
      -1 / c, 0, 0, 1 / c;
  EXPECT_LT((el.gradients[0] - expected).norm(), 1e-14);
}

TEST(TetElements, RandomTetGradientsSumToZeroAndReproduceLinearFunctions) {
  std::mt19937 rng(17);
  for (int trial = 0; trial < 20; ++trial) {
    const TetMesh mesh = randomTet(rng);
    const TetElements el = computeTetElements(mesh);
    const Matrix34& g = el.gradients[0];
    Matrix34 X;
    for (int a = 0; a < 4; ++a) X.col(a) = mesh.vertices[a];
    const double scale = g.norm() * X.norm(); // conditioning of this tet
    // Constants are reproduced (sum_a g_a = 0) and so is the identity map: sum_a X_a g_a^T = I.
    EXPECT_LT(g.rowwise().sum().norm(), 1e-14 * g.norm()) << "trial " << trial;
    EXPECT_LT((X * g.transpose() - Eigen::Matrix3d::Identity()).norm(), 1e-14 * scale) << "trial " << trial;
    Eigen::Matrix3d dm;
    dm << X.col(1) - X.col(0), X.col(2) - X.col(0), X.col(3) - X.col(0);
    EXPECT_NEAR(el.volume[0], std::abs(dm.determinant()) / 6, 1e-15);
  }
}

TEST(TetElements, InvertedTetHasPositiveVolumeAndSameGradients) {
  std::mt19937 rng(5);
  TetMesh mesh = randomTet(rng);
  const TetElements original = computeTetElements(mesh);
  // Swapping two vertices flips the orientation; volume stays positive, gradients follow the vertices.
  std::swap(mesh.tets[0][1], mesh.tets[0][2]);
  const TetElements swapped = computeTetElements(mesh);
  EXPECT_DOUBLE_EQ(swapped.volume[0], original.volume[0]);
  EXPECT_LT((swapped.gradients[0].col(1) - original.gradients[0].col(2)).norm(), 1e-12 * original.gradients[0].norm());
  EXPECT_LT((swapped.gradients[0].col(2) - original.gradients[0].col(1)).norm(), 1e-12 * original.gradients[0].norm());
}

TEST(TetElements, DeformationGradientOfAffineMapIsItsMatrix) {
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> entry(-0.5, 0.5);
  const TetMesh mesh = randomTet(rng);
  const TetElements el = computeTetElements(mesh);
  Eigen::Matrix3d A;
  for (int k = 0; k < 9; ++k) A.data()[k] = (k % 4 == 0 ? 1.0 : 0.0) + entry(rng);
  const Eigen::Vector3d shift(entry(rng), entry(rng), entry(rng));
  // x = A X + shift, so u = (A - I) X + shift and F must be A whatever the translation.
  Eigen::VectorXd u(12);
  for (int a = 0; a < 4; ++a) u.segment<3>(3 * a) = (A - Eigen::Matrix3d::Identity()) * mesh.vertices[a] + shift;
  const Matrix34 ue = tetDisplacements(mesh.tets[0], u);
  EXPECT_EQ(ue.col(2), u.segment<3>(6));
  EXPECT_LT((Eigen::Matrix3d::Identity() + displacementGradient(ue, el.gradients[0]) - A).norm(), 1e-13);
}

TEST(TetElements, DegenerateTetIsRejected) {
  // Four coplanar vertices.
  const TetMesh flat = singleTet(
      {Eigen::Vector3d::Zero(), Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(1, 1, 0)});
  EXPECT_THROW(computeTetElements(flat), std::invalid_argument);
}

} // namespace
} // namespace quiver
