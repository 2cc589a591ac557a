#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

#include "common/box_mesh.h"
#include "common/modal_rotation.h"

using namespace quiver;

// An infinitesimal rigid rotation u = omega x X has rotation omega everywhere; a pure strain
// (symmetric gradient) has none. Both are linear fields, which linear tets represent exactly.
TEST(ModalRotation, RigidRotationAndPureStrain) {
  TetMesh mesh = makeBoxMesh({1, 0.5, 0.3}, {3, 2, 2});
  std::mt19937 rng(1);
  for (auto& x : mesh.vertices) x += 0.02 * Eigen::Vector3d::Random();
  const Eigen::Vector3d omega(0.3, -0.2, 0.7);
  Eigen::Matrix3d S;
  S << 0.1, 0.02, 0.03, 0.02, -0.05, 0.01, 0.03, 0.01, 0.2;
  Eigen::MatrixXd fields(3 * mesh.vertexCount(), 2);
  for (int v = 0; v < mesh.vertexCount(); ++v) {
    fields.block<3, 1>(3 * v, 0) = omega.cross(mesh.vertices[v]);
    fields.block<3, 1>(3 * v, 1) = S * mesh.vertices[v];
  }
  const Eigen::MatrixXd w = vertexRotations(mesh, fields);
  for (int v = 0; v < mesh.vertexCount(); ++v) {
    EXPECT_LT((w.middleRows(3 * v, 3).col(0) - omega).norm(), 1e-12);
    EXPECT_LT(w.middleRows(3 * v, 3).col(1).norm(), 1e-12);
  }
}

