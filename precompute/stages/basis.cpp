#include "precompute/stages/basis.h"

#include <cmath>
#include <stdexcept>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include "precompute/distributed_dense.h"

namespace quiver {

namespace {

double orthonormalityError(Mat mass, const DofLayout& layout, const Eigen::MatrixXd& U) {
  const Eigen::MatrixXd gram = innerProducts(U, multiply(mass, U, layout), layout.comm());
  return (gram - Eigen::MatrixXd::Identity(gram.rows(), gram.cols())).cwiseAbs().maxCoeff();
}

} // namespace

double massOrthonormalize(Mat mass, const DofLayout& layout, Eigen::MatrixXd& U) {
  // Two passes: the second removes what round-off left of the first (as in Gram-Schmidt twice).
  for (int pass = 0; pass < 2; ++pass) {
    const Eigen::MatrixXd gram = innerProducts(U, multiply(mass, U, layout), layout.comm());
    Eigen::LLT<Eigen::MatrixXd> llt(gram);
    if (llt.info() != Eigen::Success || !(llt.matrixL().toDenseMatrix().diagonal().minCoeff() > 1e-8 * std::sqrt(gram.diagonal().maxCoeff())))
      throw std::runtime_error("the basis vectors are not linearly independent in the mass inner product");
    U = llt.matrixL().solve(U.transpose()).transpose();
  }
  return orthonormalityError(mass, layout, U);
}

ReducedBasis buildBasis(Mat mass, const DofLayout& layout, const LinearModes& modes,
                        const ModalDerivatives& derivatives, const BasisSettings& settings) {
  const int k = static_cast<int>(modes.eigenvalues.size());
  const int m = k + static_cast<int>(derivatives.pairs.size());
  if (settings.rank < 1 || settings.rank > m)
    throw std::runtime_error("basis rank r = " + std::to_string(settings.rank) + " must lie in [1, " +
                             std::to_string(m) + "] (k modes + k(k+1)/2 derivatives)");
  const double l1 = modes.eigenvalues[0];
  Eigen::MatrixXd A(layout.localDofs(), m);
  for (int i = 0; i < k; ++i) A.col(i) = modes.vectors.col(i) * (l1 / modes.eigenvalues[i]);
  for (size_t p = 0; p < derivatives.pairs.size(); ++p) {
    const auto [i, j] = derivatives.pairs[p];
    const double weight = (i == j ? 1.0 : std::sqrt(2.0)) * l1 * l1 / (modes.eigenvalues[i] * modes.eigenvalues[j]);
    A.col(k + static_cast<Eigen::Index>(p)) = derivatives.vectors.col(static_cast<Eigen::Index>(p)) * weight;
  }
  // Mass-PCA through the small Gram matrix A^T M A = V D V^T: U = A V_r D_r^{-1/2}.
  const Eigen::MatrixXd gram = innerProducts(A, multiply(mass, A, layout), layout.comm());
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(gram);
  if (eig.info() != Eigen::Success) throw std::runtime_error("mass-PCA: the eigen-decomposition failed");
  ReducedBasis out;
  for (int i = m - 1; i >= 0; --i) out.singularValues.push_back(std::sqrt(std::max(eig.eigenvalues()[i], 0.0)));
  const int r = settings.rank;
  if (!(out.singularValues[r - 1] > 1e-7 * out.singularValues[0]))
    throw std::runtime_error("mass-PCA: only " + std::to_string(r - 1) +
                             " independent directions above 1e-7 of the largest; ask for a smaller --rank");
  Eigen::MatrixXd V = eig.eigenvectors().rightCols(r).rowwise().reverse();
  for (int i = 0; i < r; ++i) V.col(i) /= out.singularValues[i];
  out.vectors = A * V;
  out.orthonormalityError = massOrthonormalize(mass, layout, out.vectors);
  layout.orientColumns(out.vectors);
  if (!(out.orthonormalityError <= settings.maxOrthonormalityError))
    throw std::runtime_error("basis: max |U^T M U - I| = " + std::to_string(out.orthonormalityError) +
                             " is above the limit");
  return out;
}

ReducedBasis importBasis(Mat mass, const DofLayout& layout, Eigen::MatrixXd rows, bool& wasOrthonormal) {
  wasOrthonormal = orthonormalityError(mass, layout, rows) <= 1e-8;
  ReducedBasis out;
  out.vectors = std::move(rows);
  out.orthonormalityError = massOrthonormalize(mass, layout, out.vectors);
  return out;
}

} // namespace quiver
