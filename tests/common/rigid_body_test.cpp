// The mass moments of a free object, against the box's integrals worked by hand and against the
// second moments of a deformed shape summed tet by tet.
#include "common/rigid_body.h"

#include <stdexcept>

#include <Eigen/Dense>
#include <Eigen/SparseCore>
#include <gtest/gtest.h>

#include "common/box_mesh.h"
#include "common/mass_matrix.h"

namespace quiver {
namespace {

const Eigen::Vector3d kSize(0.3, 0.5, 0.7);
constexpr double kRho = 1200.0;

std::vector<Material> uniform(const TetMesh& mesh) {
  Material m;
  m.density = kRho;
  return std::vector<Material>(mesh.tetCount(), m);
}

TEST(RigidBodyMoments, BoxMassCentreAndInertiaAreTheHandWorkedIntegrals) {
  const TetMesh mesh = makeBoxMesh(kSize, {3, 4, 5});
  const RigidBodyMoments rb = rigidBodyMoments(mesh, uniform(mesh), Eigen::MatrixXd(3 * mesh.vertexCount(), 0));
  const double m = kRho * kSize.prod();
  EXPECT_NEAR(rb.mass, m, 1e-12 * m);
  EXPECT_LT((rb.centre - kSize / 2).norm(), 1e-14);
  // A box's second moments about its centre: m s_a^2 / 12 on the diagonal, none off it.
  const Eigen::Matrix3d S = Eigen::Matrix3d(kSize.cwiseProduct(kSize).asDiagonal()) * (m / 12);
  EXPECT_LT((rb.secondMoment - S).norm(), 1e-12 * S.norm());
  const Eigen::Matrix3d I = inertiaTensor(rb.secondMoment);
  EXPECT_NEAR(I(0, 0), m * (kSize.y() * kSize.y() + kSize.z() * kSize.z()) / 12, 1e-12 * m);
}

// \int rho p_a p_b over one linear tet: rho V / 20 (sum_i p_ia p_ib + sum_i p_ia sum_i p_ib).
Eigen::Matrix3d secondMomentsSummed(const TetMesh& mesh, const Eigen::MatrixXd& p) {
  Eigen::Matrix3d S = Eigen::Matrix3d::Zero();
  for (int t = 0; t < mesh.tetCount(); ++t) {
    const double V = std::abs(signedVolume6(mesh, t)) / 6;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (int v : mesh.tets[t]) {
      S += kRho * V / 20 * p.row(v).transpose() * p.row(v);
      sum += p.row(v).transpose();
    }
    S += kRho * V / 20 * sum * sum.transpose();
  }
  return S;
}

TEST(RigidBodyMoments, DeformedSecondMomentsAreTheQuadraticInQ) {
  const TetMesh mesh = makeBoxMesh(kSize, {2, 3, 4});
  const int n = mesh.vertexCount(), r = 5;
  const Eigen::MatrixXd U = Eigen::MatrixXd::Random(3 * n, r) * 0.1;
  const RigidBodyMoments rb = rigidBodyMoments(mesh, uniform(mesh), U);
  ASSERT_EQ(rb.first.rows(), 9);
  ASSERT_EQ(rb.first.cols(), r);
  ASSERT_EQ(rb.second.size(), 9u);
  const Eigen::VectorXd q = Eigen::VectorXd::Random(r);
  const Eigen::VectorXd u = U * q;
  Eigen::MatrixXd p(n, 3);
  for (int v = 0; v < n; ++v) p.row(v) = (mesh.vertices[v] - rb.centre + u.segment<3>(3 * v)).transpose();
  const Eigen::Matrix3d expected = secondMomentsSummed(mesh, p);
  Eigen::Matrix3d fromMoments;
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b)
      fromMoments(a, b) = rb.secondMoment(a, b) + rb.first.row(3 * a + b).dot(q) + rb.first.row(3 * b + a).dot(q) +
                          q.dot(rb.second[3 * a + b] * q);
  EXPECT_LT((fromMoments - expected).norm(), 1e-12 * expected.norm());
}

TEST(RigidBodyMoments, ATranslationHasNoFirstMomentAndTheWholeMass) {
  const TetMesh mesh = makeBoxMesh(kSize, {2, 2, 2});
  Eigen::MatrixXd U = Eigen::MatrixXd::Zero(3 * mesh.vertexCount(), 1);
  for (int v = 0; v < mesh.vertexCount(); ++v) U(3 * v + 1, 0) = 1;  // every vertex along y
  const RigidBodyMoments rb = rigidBodyMoments(mesh, uniform(mesh), U);
  EXPECT_LT(rb.first.norm(), 1e-12 * rb.mass);
  EXPECT_NEAR(rb.second[3 * 1 + 1](0, 0), rb.mass, 1e-12 * rb.mass);
  EXPECT_EQ(rb.second[0](0, 0), 0.0);
  EXPECT_THROW(rigidBodyMoments(mesh, uniform(mesh), Eigen::MatrixXd(5, 1)), std::invalid_argument);
  EXPECT_THROW(restMoments(mesh, std::vector<Material>(3)), std::invalid_argument);
}

// The rest moments, summed tet by tet, are the consistent mass's: its row sums weigh the centre and
// X^T M X is S0 (to rounding), and S0 is symmetric to the bit, as a .qvr's RIGID_BODY must be.
TEST(RigidBodyMoments, RestMomentsAreTheConsistentMassMoments) {
  const TetMesh mesh = makeBoxMesh(kSize, {3, 2, 4});
  TetMesh skewed = mesh;
  for (Eigen::Vector3d& x : skewed.vertices) x += Eigen::Vector3d(0.3 * x.y() * x.z(), 0.1 * x.x() * x.x(), 0.05 * x.y());
  std::vector<Material> materials = uniform(skewed);
  for (size_t t = 0; t < materials.size(); ++t) materials[t].density *= 1 + 0.1 * static_cast<double>(t % 7);
  const RestMoments rest = restMoments(skewed, materials);
  const Eigen::SparseMatrix<double> M = consistentMassMatrix(skewed, materials);
  Eigen::MatrixXd X(3 * skewed.vertexCount(), 3);
  X.setZero();
  for (int v = 0; v < skewed.vertexCount(); ++v)
    for (int a = 0; a < 3; ++a) X(3 * v + a, a) = 1;  // translations
  const Eigen::MatrixXd MX = M * X;
  double mass = 0;
  Eigen::Vector3d first = Eigen::Vector3d::Zero();
  for (int v = 0; v < skewed.vertexCount(); ++v) {
    mass += MX(3 * v, 0);
    first += MX(3 * v, 0) * skewed.vertices[v];
  }
  const Eigen::Vector3d centre = first / mass;
  Eigen::MatrixXd Y(3 * skewed.vertexCount(), 3);  // columns: (X - c)_a, one per component
  Y.setZero();
  for (int v = 0; v < skewed.vertexCount(); ++v)
    for (int a = 0; a < 3; ++a) Y(3 * v, a) = skewed.vertices[v](a) - centre(a);
  const Eigen::Matrix3d S = Y.transpose() * (M * Y);
  EXPECT_NEAR(rest.mass, mass, 1e-13 * mass);
  EXPECT_LT((rest.centre - centre).norm(), 1e-14);
  EXPECT_LT((rest.secondMoment - S).norm(), 1e-13 * S.norm());
  EXPECT_EQ(rest.secondMoment, rest.secondMoment.transpose());
}

} // namespace
} // namespace quiver
