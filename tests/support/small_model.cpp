#include "tests/support/small_model.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include "common/box_mesh.h"
#include "common/mass_matrix.h"
#include "common/mesh_checks.h"
#include "common/reduced_energy.h"
#include "common/stvk_force_model.h"
#include "formats/model_contents.h"

namespace quiver::test {

ModelContents smallBeamModel(const SmallModelSpec& spec) {
  RawMesh raw;
  raw.mesh = makeBoxMesh(spec.size, spec.cells);
  raw.source.file = "small beam";
  for (int t = 0; t < raw.mesh.tetCount(); ++t) raw.source.addTet(t + 1, t + 1);
  for (int v = 0; v < raw.mesh.vertexCount(); ++v) raw.source.vertexFileId.push_back(v + 1);
  const CheckedMesh mesh = checkMesh(std::move(raw));
  const TetMesh& m = mesh.mesh;
  Material material;
  material.youngsModulus = spec.youngsModulus;
  material.poissonRatio = spec.poissonRatio;
  material.density = spec.density;
  const std::vector<Material> perTet(m.tetCount(), material);

  // Free DOFs: every vertex off the clamped face x = 0 (all of them for a free object).
  std::vector<int> free;
  for (int v = 0; v < m.vertexCount(); ++v)
    if (spec.free || m.vertices[v].x() > 1e-9)
      for (int c = 0; c < 3; ++c) free.push_back(3 * v + c);
  const int n = static_cast<int>(free.size());
  const StVKForceModel stvk(m, perTet);
  const Eigen::MatrixXd K0 = Eigen::MatrixXd(stvk.tangentStiffness(Eigen::VectorXd::Zero(stvk.dofCount())));
  const Eigen::MatrixXd M = Eigen::MatrixXd(consistentMassMatrix(m, perTet));
  Eigen::MatrixXd Kf(n, n), Mf(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      Kf(i, j) = K0(free[i], free[j]);
      Mf(i, j) = M(free[i], free[j]);
    }
  const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eig(Kf, Mf);
  const auto full = [&](const Eigen::VectorXd& onFree) {
    Eigen::VectorXd u = Eigen::VectorXd::Zero(stvk.dofCount());
    for (int i = 0; i < n; ++i) u[free[i]] = onFree[i];
    return u;
  };

  // The bake's recipe (precompute/stages/basis.h): modes scaled by lambda_1 / lambda_i, every
  // modal derivative K Psi_ij = -H(phi_i, phi_j) scaled by lambda_1^2 / (lambda_i lambda_j) (and
  // sqrt 2 for i != j) at spec.derivativeAmplitude, then mass-PCA: the r dominant directions in
  // the M inner product.
  // A free object's first six eigenpairs are its rigid motions: the modes start after them, and
  // the derivatives are solved in their M-orthogonal complement (K is singular on the rigid motions).
  const int k = spec.modes, first = spec.free ? 6 : 0;
  const Eigen::MatrixXd phi = eig.eigenvectors().rightCols(n - first);
  const Eigen::VectorXd lambda = eig.eigenvalues().tail(n - first);
  std::vector<double> eigenvalues(lambda.data(), lambda.data() + k);
  const double l1 = eigenvalues[0];
  Eigen::MatrixXd scaled(n, k + k * (k + 1) / 2);
  for (int i = 0; i < k; ++i) scaled.col(i) = phi.col(i) * (l1 / eigenvalues[i]);
  const Eigen::LLT<Eigen::MatrixXd> clamped(Kf);
  const auto solve = [&](const Eigen::VectorXd& h) {  // free: K x = h for x M-orthogonal to the rigid motions
    return spec.free ? Eigen::VectorXd(phi * (phi.transpose() * h).cwiseQuotient(lambda)) : Eigen::VectorXd(clamped.solve(h));
  };
  int column = k;
  for (int i = 0; i < k; ++i)
    for (int j = i; j < k; ++j) {
      Eigen::VectorXd h, hf(n);
      stvk.forceHessianAtRest(full(phi.col(i)), full(phi.col(j)), h);
      for (int d = 0; d < n; ++d) hf[d] = -h[free[d]];
      const double weight = spec.derivativeAmplitude * (i == j ? 1.0 : std::sqrt(2.0)) * l1 * l1 / (eigenvalues[i] * eigenvalues[j]);
      scaled.col(column++) = solve(hf) * weight;
    }
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> pca(scaled.transpose() * Mf * scaled);
  const int last = static_cast<int>(scaled.cols()) - 1;
  Eigen::MatrixXd vectors(n, spec.rank);
  for (int j = 0; j < spec.rank; ++j)
    vectors.col(j) = scaled * pca.eigenvectors().col(last - j) / std::sqrt(pca.eigenvalues()[last - j]);
  Eigen::MatrixXd U = Eigen::MatrixXd::Zero(stvk.dofCount(), vectors.cols());
  for (int j = 0; j < vectors.cols(); ++j) U.col(j) = full(vectors.col(j));

  const int r = static_cast<int>(U.cols());
  const Eigen::MatrixXd gram = reducedEnergyGram(m, perTet, U);
  Eigen::MatrixXd axes = Eigen::MatrixXd::Zero(stvk.dofCount(), 3);
  for (int i = 0; i < stvk.dofCount(); ++i) axes(i, i % 3) = 1;
  const Eigen::MatrixXd gravity = U.transpose() * M * axes;  // r x 3
  ExportSettings settings;
  settings.basisPrecision = spec.basisPrecision;
  settings.rigidBody = spec.free;
  return makeModelContents(mesh, perTet, U, energyCoefficientsFromGram(gram.data(), gram.rows(), r), eigenvalues,
                           gravity, settings);
}

} // namespace quiver::test
