// Mass matrices of a box mesh checked against integrals of the box computed by hand.
#include "common/mass_matrix.h"

#include <cmath>
#include <ostream>
#include <stdexcept>
#include <string>

#include <Eigen/Dense>
#include <Eigen/SparseCholesky>
#include <gtest/gtest.h>

#include "common/box_mesh.h"

namespace quiver {
namespace {

const Eigen::Vector3d kSize(0.3, 0.5, 0.7);
constexpr double kRho = 1200.0;

Material material(double density) {
  Material m;
  m.density = density;
  return m;
}

// The 3n-vector with value(X_v) in component c of every vertex v, zero elsewhere.
template <class Fn>
Eigen::VectorXd field(const TetMesh& mesh, int c, Fn value) {
  Eigen::VectorXd out = Eigen::VectorXd::Zero(3 * mesh.vertexCount());
  for (int v = 0; v < mesh.vertexCount(); ++v) out[3 * v + c] = value(mesh.vertices[v]);
  return out;
}

struct MassCase {
  const char* name;
  Eigen::SparseMatrix<double> (*build)(const TetMesh&, const std::vector<Material>&);
};

// Names the case in gtest's output instead of dumping its bytes.
void PrintTo(const MassCase& c, std::ostream* os) { *os << c.name; }

class MassMatrix : public ::testing::TestWithParam<MassCase> {};

TEST_P(MassMatrix, TotalMassIsDensityTimesBoxVolume) {
  const TetMesh mesh = makeBoxMesh(kSize, {2, 3, 4});
  const Eigen::SparseMatrix<double> M = GetParam().build(mesh, std::vector<Material>(mesh.tetCount(), material(kRho)));
  const double mass = kRho * kSize.prod();
  for (int c = 0; c < 3; ++c) {
    const Eigen::VectorXd one = field(mesh, c, [](const Eigen::Vector3d&) { return 1.0; });
    EXPECT_NEAR(one.dot(M * one), mass, 1e-12 * mass) << "component " << c;
    // Components do not couple.
    const Eigen::VectorXd other = field(mesh, (c + 1) % 3, [](const Eigen::Vector3d&) { return 1.0; });
    EXPECT_EQ(other.dot(M * one), 0.0);
  }
}

TEST_P(MassMatrix, SymmetricPositiveDefinite) {
  const TetMesh mesh = makeBoxMesh(kSize, {2, 2, 3});
  const Eigen::SparseMatrix<double> M = GetParam().build(mesh, std::vector<Material>(mesh.tetCount(), material(kRho)));
  ASSERT_EQ(M.rows(), 3 * mesh.vertexCount());
  ASSERT_EQ(M.cols(), 3 * mesh.vertexCount());
  const Eigen::SparseMatrix<double> Mt = M.transpose();
  EXPECT_EQ((M - Mt).norm(), 0.0);
  Eigen::SimplicialLLT<Eigen::SparseMatrix<double>> cholesky(M);
  EXPECT_EQ(cholesky.info(), Eigen::Success);
  // Cholesky alone would accept a tiny pivot; the smallest eigenvalue must be a real mass.
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(Eigen::MatrixXd(M), Eigen::EigenvaluesOnly);
  EXPECT_GT(eig.eigenvalues().minCoeff(), 1e-3 * eig.eigenvalues().maxCoeff());
}

TEST_P(MassMatrix, FirstMomentOfLinearFieldIsExact) {
  // 1^T M x_c = \int rho X_c dV = rho * L_c^2 / 2 * (product of the other two sides).
  const TetMesh mesh = makeBoxMesh(kSize, {3, 2, 2});
  const Eigen::SparseMatrix<double> M = GetParam().build(mesh, std::vector<Material>(mesh.tetCount(), material(kRho)));
  for (int c = 0; c < 3; ++c) {
    const Eigen::VectorXd one = field(mesh, c, [](const Eigen::Vector3d&) { return 1.0; });
    const Eigen::VectorXd x = field(mesh, c, [c](const Eigen::Vector3d& X) { return X[c]; });
    const double expected = kRho * kSize.prod() * kSize[c] / 2;
    EXPECT_NEAR(one.dot(M * x), expected, 1e-12 * expected) << "component " << c;
  }
}

TEST_P(MassMatrix, PerTetDensityIsHonoured) {
  // Two cells along x: tets with centroid x < L_x / 2 are the left half of the box exactly.
  const TetMesh mesh = makeBoxMesh(kSize, {2, 1, 1});
  std::vector<Material> perTet;
  for (const Tet& t : mesh.tets) {
    double cx = 0;
    for (int v : t) cx += mesh.vertices[v].x() / 4;
    perTet.push_back(material(cx < kSize.x() / 2 ? 500.0 : 3000.0));
  }
  const Eigen::SparseMatrix<double> M = GetParam().build(mesh, perTet);
  const Eigen::VectorXd one = field(mesh, 1, [](const Eigen::Vector3d&) { return 1.0; });
  const double expected = (500.0 + 3000.0) / 2 * kSize.prod();
  EXPECT_NEAR(one.dot(M * one), expected, 1e-12 * expected);
}

TEST_P(MassMatrix, WrongMaterialCountThrows) {
  const TetMesh mesh = makeBoxMesh(kSize, {1, 1, 1});
  EXPECT_THROW(GetParam().build(mesh, std::vector<Material>(mesh.tetCount() - 1)), std::invalid_argument);
}

INSTANTIATE_TEST_SUITE_P(Kinds, MassMatrix,
                         ::testing::Values(MassCase{"Consistent", consistentMassMatrix},
                                           MassCase{"Lumped", lumpedMassMatrix}),
                         [](const ::testing::TestParamInfo<MassCase>& p) { return std::string(p.param.name); });

TEST(MassMatrixKinds, OnlyConsistentMassIntegratesTheSecondMoment) {
  // x^T M x = \int rho X^2 dV = rho L_x^3 / 3 L_y L_z: a product of two linear fields, exact for
  // the consistent mass only. Checking that lumping misses it shows the test can tell them apart.
  const TetMesh mesh = makeBoxMesh(kSize, {2, 2, 2});
  const std::vector<Material> perTet(mesh.tetCount(), material(kRho));
  const Eigen::VectorXd x = field(mesh, 0, [](const Eigen::Vector3d& X) { return X.x(); });
  const double expected = kRho * std::pow(kSize.x(), 3) / 3 * kSize.y() * kSize.z();
  EXPECT_NEAR(x.dot(consistentMassMatrix(mesh, perTet) * x), expected, 1e-12 * expected);
  EXPECT_GT(std::abs(x.dot(lumpedMassMatrix(mesh, perTet) * x) - expected), 1e-2 * expected);
}

TEST(MassMatrixKinds, LumpedMassIsDiagonalRowSumOfConsistent) {
  const TetMesh mesh = makeBoxMesh(kSize, {2, 2, 1});
  const std::vector<Material> perTet(mesh.tetCount(), material(kRho));
  const Eigen::SparseMatrix<double> lumped = lumpedMassMatrix(mesh, perTet);
  const Eigen::VectorXd rowSums = consistentMassMatrix(mesh, perTet) * Eigen::VectorXd::Ones(3 * mesh.vertexCount());
  const Eigen::MatrixXd dense(lumped);
  EXPECT_EQ((dense - Eigen::MatrixXd(dense.diagonal().asDiagonal())).norm(), 0.0);
  EXPECT_LT((dense.diagonal() - rowSums).norm(), 1e-12 * rowSums.norm());
}

} // namespace
} // namespace quiver
