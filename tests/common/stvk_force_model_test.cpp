// The St.Venant-Kirchhoff model checked against what needs no trust in the code: finite
// differences of its own energy and force, the rigid-motion null space, frame invariance, and
// the analytic stress of a uniform deformation (patch test).
#include "common/stvk_force_model.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include "common/box_mesh.h"

namespace quiver {
namespace {

Material material(double youngs, double poisson) {
  Material m;
  m.youngsModulus = youngs;
  m.poissonRatio = poisson;
  return m;
}

struct Body {
  TetMesh mesh;
  std::vector<Material> perTet;
};

// A 2x2x2-cell box of one material.
Body boxBody() {
  Body b{makeBoxMesh(Eigen::Vector3d(1.0, 0.8, 0.6), {2, 2, 2}), {}};
  b.perTet.assign(b.mesh.tetCount(), material(1e6, 0.45));
  return b;
}

// The same box with every vertex moved randomly by up to 15% of a cell, and two materials
// (stiffer, nearly incompressible and softer, compressible) on alternating tets.
Body jitteredTwoMaterialBody(std::mt19937& rng) {
  Body b = boxBody();
  std::uniform_real_distribution<double> jitter(-0.15, 0.15);
  const Eigen::Vector3d cell(0.5, 0.4, 0.3);
  for (auto& x : b.mesh.vertices) x += cell.cwiseProduct(Eigen::Vector3d(jitter(rng), jitter(rng), jitter(rng)));
  for (int t = 0; t < b.mesh.tetCount(); ++t) {
    EXPECT_GT(signedVolume6(b.mesh, t), 0) << "jitter inverted tet " << t;
    b.perTet[t] = t % 2 ? material(5e6, 0.45) : material(1e6, 0.3);
  }
  return b;
}

// A measured value for the test report (RecordProperty keeps strings; to_string would round to 1e-6).
std::string sci(double x) {
  std::ostringstream out;
  out << std::scientific << x;
  return out.str();
}

Eigen::VectorXd randomDisplacement(int n, double amplitude, std::mt19937& rng) {
  std::uniform_real_distribution<double> d(-amplitude, amplitude);
  Eigen::VectorXd u(n);
  for (int i = 0; i < n; ++i) u[i] = d(rng);
  return u;
}

Eigen::Matrix3d randomRotation(std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  return Eigen::Quaterniond(n(rng), n(rng), n(rng), n(rng)).normalized().toRotationMatrix();
}

// u' such that X + u' = Q (X + u): the deformed shape rigidly rotated.
Eigen::VectorXd rotateDeformedShape(const TetMesh& mesh, const Eigen::VectorXd& u, const Eigen::Matrix3d& Q) {
  Eigen::VectorXd out(u.size());
  for (int v = 0; v < mesh.vertexCount(); ++v) {
    const Eigen::Vector3d& X = mesh.vertices[v];
    out.segment<3>(3 * v) = Q * (X + u.segment<3>(3 * v)) - X;
  }
  return out;
}

// Central differences of the energy: error O(h^2) from truncation plus eps * energy / h.
double forceGradientError(const Body& body, double amplitude, std::mt19937& rng) {
  const StVKForceModel model(body.mesh, body.perTet);
  Eigen::VectorXd u = randomDisplacement(model.dofCount(), amplitude, rng);
  Eigen::VectorXd f;
  model.internalForce(u, f);
  const double h = 1e-6;
  Eigen::VectorXd fd(u.size());
  for (int i = 0; i < u.size(); ++i) {
    const double ui = u[i];
    u[i] = ui + h;
    const double ePlus = model.energy(u);
    u[i] = ui - h;
    const double eMinus = model.energy(u);
    u[i] = ui;
    fd[i] = (ePlus - eMinus) / (2 * h);
  }
  return (fd - f).norm() / f.norm();
}

TEST(StVKForceModel, RestStateHasNoEnergyOrForce) {
  const Body body = boxBody();
  const StVKForceModel model(body.mesh, body.perTet);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(model.dofCount());
  Eigen::VectorXd f;
  model.internalForce(zero, f);
  EXPECT_EQ(model.energy(zero), 0.0);
  EXPECT_EQ(f.size(), model.dofCount());
  EXPECT_EQ(f.norm(), 0.0);
}

TEST(StVKForceModel, StressFunctionsMatchUniaxialStretch) {
  // F = diag(s, 1, 1): E_xx = (s^2 - 1)/2, S = diag(lambda + 2 mu, lambda, lambda) E_xx,
  // W = (mu + lambda/2) E_xx^2.
  const double s = 1.3, lambda = 2.0, mu = 0.7, exx = (s * s - 1) / 2;
  const Eigen::Matrix3d E = greenStrain(Eigen::Vector3d(s - 1, 0, 0).asDiagonal());  // F = diag(s, 1, 1)
  EXPECT_LT((E - Eigen::Vector3d(exx, 0, 0).asDiagonal().toDenseMatrix()).norm(), 1e-15);
  const Eigen::Matrix3d S = stvkSecondPiolaKirchhoff(E, lambda, mu);
  EXPECT_LT((S - Eigen::Vector3d(lambda + 2 * mu, lambda, lambda).asDiagonal().toDenseMatrix() * exx).norm(), 1e-14);
  EXPECT_NEAR(stvkEnergyDensity(E, lambda, mu), (mu + lambda / 2) * exx * exx, 1e-15);
}

TEST(StVKForceModel, ForceIsEnergyGradientOnBox) {
  std::mt19937 rng(1);
  const double error = forceGradientError(boxBody(), 0.1, rng);
  RecordProperty("relative_error", sci(error));
  EXPECT_LT(error, 1e-6);
}

TEST(StVKForceModel, ForceIsEnergyGradientOnJitteredTwoMaterialMesh) {
  std::mt19937 rng(2);
  const Body body = jitteredTwoMaterialBody(rng);
  const double error = forceGradientError(body, 0.1, rng);
  RecordProperty("relative_error", sci(error));
  EXPECT_LT(error, 1e-6);
}

class TangentStiffness : public ::testing::TestWithParam<bool> {};

TEST_P(TangentStiffness, IsForceDerivativeAtLargeDeformation) {
  std::mt19937 rng(3);
  const Body body = GetParam() ? jitteredTwoMaterialBody(rng) : boxBody();
  const StVKForceModel model(body.mesh, body.perTet);
  // Up to 30% of the box's smallest side: strains of order one, some tets inverted.
  Eigen::VectorXd u = randomDisplacement(model.dofCount(), 0.18, rng);
  const Eigen::MatrixXd K(model.tangentStiffness(u));
  const double h = 1e-6;
  Eigen::MatrixXd fd(K.rows(), K.cols());
  Eigen::VectorXd fPlus, fMinus;
  for (int j = 0; j < u.size(); ++j) {
    const double uj = u[j];
    u[j] = uj + h;
    model.internalForce(u, fPlus);
    u[j] = uj - h;
    model.internalForce(u, fMinus);
    u[j] = uj;
    fd.col(j) = (fPlus - fMinus) / (2 * h);
  }
  const double error = (fd - K).norm() / K.norm();
  RecordProperty("relative_error", sci(error));
  EXPECT_LT(error, 1e-6);
  EXPECT_LE((K - K.transpose()).norm(), 1e-14 * K.norm());
}

INSTANTIATE_TEST_SUITE_P(Meshes, TangentStiffness, ::testing::Bool(),
                         [](const ::testing::TestParamInfo<bool>& p) {
                           return std::string(p.param ? "JitteredTwoMaterials" : "Box");
                         });

// K(u) is quadratic in u, so the central difference of K along b is exact up to round-off:
// d^2R[a, b] = (K(eps b) - K(-eps b)) a / (2 eps). A second check differentiates the force twice.
TEST(StVKForceModel, ForceHessianAtRestIsTheDerivativeOfTheTangent) {
  std::mt19937 rng(11);
  Body body = jitteredTwoMaterialBody(rng);
  StVKForceModel model(body.mesh, body.perTet);
  const int n = model.dofCount();
  const Eigen::VectorXd a = randomDisplacement(n, 0.1, rng), b = randomDisplacement(n, 0.1, rng);
  Eigen::VectorXd ab, ba;
  model.forceHessianAtRest(a, b, ab);
  model.forceHessianAtRest(b, a, ba);
  const double eps = 1e-3;
  const Eigen::VectorXd fromTangent = (model.tangentStiffness(eps * b) - model.tangentStiffness(-eps * b)) * a / (2 * eps);
  const double tangentError = (ab - fromTangent).norm() / fromTangent.norm();
  EXPECT_LT(tangentError, 1e-10);
  EXPECT_LT((ab - ba).norm(), 1e-13 * ab.norm());

  Eigen::VectorXd fpp, fpm, fmp, fmm;
  const double h = 1e-3;
  model.internalForce(h * (a + b), fpp);
  model.internalForce(h * (a - b), fpm);
  model.internalForce(h * (b - a), fmp);
  model.internalForce(-h * (a + b), fmm);
  const Eigen::VectorXd fromForce = (fpp - fpm - fmp + fmm) / (4 * h * h);
  const double forceError = (ab - fromForce).norm() / fromForce.norm();
  EXPECT_LT(forceError, 1e-6);
  RecordProperty("hessian_vs_tangent_fd", sci(tangentError));
  RecordProperty("hessian_vs_force_fd", sci(forceError));
}

TEST(StVKForceModel, RestStiffnessHasExactlySixRigidModes) {
  std::mt19937 rng(4);
  const Body body = jitteredTwoMaterialBody(rng);
  const StVKForceModel model(body.mesh, body.perTet);
  const Eigen::MatrixXd K0(model.tangentStiffness(Eigen::VectorXd::Zero(model.dofCount())));
  EXPECT_LE((K0 - K0.transpose()).norm(), 1e-14 * K0.norm());

  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(K0, Eigen::EigenvaluesOnly);
  const Eigen::VectorXd& lambda = eig.eigenvalues(); // ascending
  const double largest = lambda.cwiseAbs().maxCoeff();
  for (int i = 0; i < 6; ++i) EXPECT_LT(std::abs(lambda[i]), 1e-8 * largest) << "eigenvalue " << i;
  EXPECT_GT(lambda[6], 1e-4 * largest);
  RecordProperty("zero_eigenvalue_ratio", sci(lambda.head<6>().cwiseAbs().maxCoeff() / largest));
  RecordProperty("seventh_eigenvalue_ratio", sci(lambda[6] / largest));

  // The null space is the rigid motions: translations t and infinitesimal rotations w x X.
  for (int k = 0; k < 3; ++k) {
    Eigen::VectorXd translation(model.dofCount()), rotation(model.dofCount());
    for (int v = 0; v < body.mesh.vertexCount(); ++v) {
      translation.segment<3>(3 * v) = Eigen::Vector3d::Unit(k);
      rotation.segment<3>(3 * v) = Eigen::Vector3d::Unit(k).cross(body.mesh.vertices[v]);
    }
    EXPECT_LT((K0 * translation).norm(), 1e-10 * largest * translation.norm());
    EXPECT_LT((K0 * rotation).norm(), 1e-10 * largest * rotation.norm());
  }
}

TEST(StVKForceModel, EnergyAndForceAreInvariantUnderRotationOfDeformedShape) {
  std::mt19937 rng(5);
  const Body body = jitteredTwoMaterialBody(rng);
  const StVKForceModel model(body.mesh, body.perTet);
  const Eigen::VectorXd u = randomDisplacement(model.dofCount(), 0.1, rng);
  const Eigen::Matrix3d Q = randomRotation(rng);
  const Eigen::VectorXd rotated = rotateDeformedShape(body.mesh, u, Q);

  const double e = model.energy(u);
  EXPECT_NEAR(model.energy(rotated), e, 1e-10 * e);
  // Forces are vectors in the deformed frame: they turn with it (P = F S, F -> Q F).
  Eigen::VectorXd f, fRotated;
  model.internalForce(u, f);
  model.internalForce(rotated, fRotated);
  for (int v = 0; v < body.mesh.vertexCount(); ++v)
    EXPECT_LT((fRotated.segment<3>(3 * v) - Q * f.segment<3>(3 * v)).norm(), 1e-10 * f.norm()) << "vertex " << v;
}

TEST(StVKForceModel, PureRotationCostsNoEnergyUnlikeLinearElasticity) {
  const Body body = boxBody();
  const StVKForceModel model(body.mesh, body.perTet);
  const Eigen::Matrix3d Q = Eigen::AngleAxisd(0.5, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Eigen::VectorXd u = rotateDeformedShape(body.mesh, Eigen::VectorXd::Zero(model.dofCount()), Q);
  const double scale = body.perTet[0].mu() * totalVolume(body.mesh); // energy of a unit strain
  const Eigen::SparseMatrix<double> K0 = model.tangentStiffness(Eigen::VectorXd::Zero(model.dofCount()));
  const double linear = 0.5 * u.dot(K0 * u);
  RecordProperty("stvk_energy_over_scale", sci(model.energy(u) / scale));
  RecordProperty("linear_energy_over_scale", sci(linear / scale));
  EXPECT_LT(std::abs(model.energy(u)), 1e-12 * scale);
  EXPECT_GT(linear, 1e-2 * scale);
}

// StVK for a uniform F, written out here from the formulas rather than taken from the model.
struct AnalyticStVK {
  double W;          // energy density
  Eigen::Matrix3d P; // first Piola-Kirchhoff stress
};

AnalyticStVK analyticStVK(const Eigen::Matrix3d& F, const Material& m) {
  const double lambda = m.youngsModulus * m.poissonRatio / ((1 + m.poissonRatio) * (1 - 2 * m.poissonRatio));
  const double mu = m.youngsModulus / (2 * (1 + m.poissonRatio));
  const Eigen::Matrix3d E = 0.5 * (F.transpose() * F - Eigen::Matrix3d::Identity());
  double EE = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) EE += E(i, j) * E(i, j);
  const double trE = E(0, 0) + E(1, 1) + E(2, 2);
  return {mu * EE + 0.5 * lambda * trE * trE, F * (2 * mu * E + lambda * trE * Eigen::Matrix3d::Identity())};
}

// A stretch with shear; det F > 0.
Eigen::Matrix3d patchF() {
  Eigen::Matrix3d F;
  F << 1.15, 0.20, -0.05, //
      0.10, 0.90, 0.12,   //
      0.00, -0.08, 1.05;
  return F;
}

// u = (F - I) X at every vertex.
Eigen::VectorXd uniformDeformation(const TetMesh& mesh, const Eigen::Matrix3d& F) {
  Eigen::VectorXd u(3 * mesh.vertexCount());
  for (int v = 0; v < mesh.vertexCount(); ++v) u.segment<3>(3 * v) = (F - Eigen::Matrix3d::Identity()) * mesh.vertices[v];
  return u;
}

TEST(StVKForceModel, PatchTestUniformDeformationMatchesAnalyticStress) {
  const Eigen::Vector3d L(1.2, 0.9, 0.6);
  const TetMesh mesh = makeBoxMesh(L, {3, 3, 3});
  const Material m = material(2e6, 0.35);
  const StVKForceModel model(mesh, std::vector<Material>(mesh.tetCount(), m));
  const Eigen::VectorXd u = uniformDeformation(mesh, patchF());
  const auto [W, P] = analyticStVK(patchF(), m);
  const double volume = L.prod();
  EXPECT_NEAR(model.energy(u), volume * W, 1e-12 * volume * W);

  Eigen::VectorXd f;
  model.internalForce(u, f);
  double largest = 0;
  for (int v = 0; v < mesh.vertexCount(); ++v) largest = std::max(largest, f.segment<3>(3 * v).norm());
  // Nodal forces are \int_{boundary} N_a P n dA (div P = 0): zero inside, and the vertices of the
  // face x = L_x carry its traction P e_x L_y L_z. (Edge vertices also pick up traction from the
  // side faces, but opposite side faces are meshed alike, so those parts cancel in the sum.)
  Eigen::Vector3d faceTotal = Eigen::Vector3d::Zero(), total = Eigen::Vector3d::Zero();
  int interior = 0;
  for (int v = 0; v < mesh.vertexCount(); ++v) {
    const Eigen::Vector3d& X = mesh.vertices[v];
    const Eigen::Vector3d fv = f.segment<3>(3 * v);
    total += fv;
    if (std::abs(X.x() - L.x()) < 1e-12) faceTotal += fv;
    if ((X.array() > 1e-12).all() && (X.array() < L.array() - 1e-12).all()) {
      ++interior;
      EXPECT_LT(fv.norm(), 1e-9 * largest) << "interior vertex " << v;
    }
  }
  EXPECT_EQ(interior, 8);
  const Eigen::Vector3d traction = P * Eigen::Vector3d::UnitX() * L.y() * L.z();
  EXPECT_LT((faceTotal - traction).norm(), 1e-10 * traction.norm());
  EXPECT_LT(total.norm(), 1e-10 * traction.norm());
}

TEST(StVKForceModel, PerTetMaterialsAreHonoured) {
  // Left and right halves of the box (two cells along x) in different materials.
  const Eigen::Vector3d L(1.0, 0.5, 0.5);
  const TetMesh mesh = makeBoxMesh(L, {2, 1, 1});
  const Material left = material(1e6, 0.3), right = material(7e6, 0.45);
  std::vector<Material> perTet;
  for (const Tet& t : mesh.tets) {
    double cx = 0;
    for (int v : t) cx += mesh.vertices[v].x() / 4;
    perTet.push_back(cx < L.x() / 2 ? left : right);
  }
  const StVKForceModel model(mesh, perTet);
  const double expected = L.prod() / 2 * (analyticStVK(patchF(), left).W + analyticStVK(patchF(), right).W);
  EXPECT_NEAR(model.energy(uniformDeformation(mesh, patchF())), expected, 1e-12 * expected);
}

TEST(StVKForceModel, RefillKeepsStorageAndMatchesFreshAssembly) {
  std::mt19937 rng(6);
  const Body body = jitteredTwoMaterialBody(rng);
  const StVKForceModel model(body.mesh, body.perTet);
  Eigen::SparseMatrix<double> K = model.tangentStiffness(randomDisplacement(model.dofCount(), 0.1, rng));
  const double* values = K.valuePtr();
  const int* rows = K.innerIndexPtr();
  const Eigen::VectorXd u = randomDisplacement(model.dofCount(), 0.1, rng);
  model.tangentStiffness(u, K);
  EXPECT_EQ(K.valuePtr(), values);
  EXPECT_EQ(K.innerIndexPtr(), rows);
  const Eigen::SparseMatrix<double> fresh = model.tangentStiffness(u);
  EXPECT_EQ((K - fresh).norm(), 0.0);
  // A matrix without the pattern gets it.
  Eigen::SparseMatrix<double> empty;
  model.tangentStiffness(u, empty);
  EXPECT_EQ((empty - fresh).norm(), 0.0);
}

TEST(StVKForceModel, RejectsMismatchedSizes) {
  const Body body = boxBody();
  EXPECT_THROW(StVKForceModel(body.mesh, std::vector<Material>(3)), std::invalid_argument);
  const StVKForceModel model(body.mesh, body.perTet);
  EXPECT_THROW(model.energy(Eigen::VectorXd::Zero(model.dofCount() + 3)), std::invalid_argument);
}

} // namespace
} // namespace quiver
