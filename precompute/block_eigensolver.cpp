#include "precompute/block_eigensolver.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>

#include <Eigen/Eigenvalues>

#include "precompute/distributed_dense.h"

namespace quiver {

namespace {

using Eigen::MatrixXd;

// Uniform in [-0.5, 0.5), from (vertex, component, column, seed) alone (splitmix64): the same start
// every run and on any rank count (PETSc's row numbering follows the partition; vertices do not).
double startEntry(uint64_t row, uint64_t column, uint64_t seed) {
  uint64_t z = row * 0x9E3779B97F4A7C15ull + column * 0xBF58476D1CE4E5B9ull + seed * 0x94D049BB133111EBull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  z ^= z >> 31;
  return static_cast<double>(z >> 11) * 0x1.0p-53 - 0.5;
}

MatrixXd product(Eigen::Ref<const MatrixXd> A, Eigen::Ref<const MatrixXd> B) {
  MatrixXd C(A.rows(), B.cols());
  multiplyInto(A, false, B, 1.0, 0.0, C);
  return C;
}

// A block Z made M-orthogonal to `deflation` and to the basis V (twice: classical Gram-Schmidt with
// one re-orthogonalisation), then M-orthonormal within itself (SVQB), dropping directions whose norm
// fell below 1e-13 of the block's: there the Krylov space has closed, and what is left is rounding.
// MZ = M Z is formed from the projected block (updates of an earlier product drift once SVQB divides
// by small norms). Returns V^T M Z as it came in, the Rayleigh quotient's new column, and the
// M-Gram matrix of what the projection left (the residual estimate's).
struct Orthonormalizer {
  const MatrixXd& deflation;
  const MatrixXd& massDeflation;
  Mat mass;
  const DofLayout& layout;
  int64_t room;  // the dimension of the space M-orthogonal to `deflation`

  MatrixXd operator()(Eigen::Ref<const MatrixXd> V, Eigen::Ref<const MatrixXd> MV, MatrixXd& Z, MatrixXd& MZ,
                      MatrixXd* projectedGram) const {
    const MPI_Comm comm = layout.comm();
    MatrixXd coefficients = MatrixXd::Zero(V.cols(), Z.cols());
    if (projectedGram) projectedGram->resize(0, 0);
    if (Z.cols() == 0) MZ.resize(Z.rows(), 0);
    bool freshProduct = true;  // pass 0 forms M Z; pass 1 again if pass 0 scaled up tiny directions
    for (int pass = 0; pass < 2 && Z.cols() > 0; ++pass) {
      if (deflation.cols() > 0) {
        const MatrixXd d = innerProducts(massDeflation, Z, comm);
        multiplyInto(deflation, false, d, -1.0, 1.0, Z);
        if (!freshProduct) multiplyInto(massDeflation, false, d, -1.0, 1.0, MZ);
      }
      MatrixXd c = MatrixXd::Zero(V.cols(), Z.cols());
      if (V.cols() > 0) {
        c = innerProducts(MV, Z, comm);
        multiplyInto(V, false, c, -1.0, 1.0, Z);
        if (!freshProduct) multiplyInto(MV, false, c, -1.0, 1.0, MZ);
      }
      if (freshProduct) MZ = multiply(mass, Z, layout);
      MatrixXd gram = innerProducts(Z, MZ, comm);
      gram = 0.5 * (gram + gram.transpose());
      // The block's squared norms as it came in: projected away plus what is left (V is M-orthonormal).
      const double scale = pass == 0 ? (c.colwise().squaredNorm().transpose() + gram.diagonal()).maxCoeff()
                                     : gram.diagonal().maxCoeff();
      if (pass == 0) {
        coefficients = c;
        if (projectedGram) *projectedGram = gram;
      }
      // Largest first; at most `room` - V's columns (past that the space is exhausted: rounding).
      const Eigen::SelfAdjointEigenSolver<MatrixXd> e(gram);
      std::vector<Eigen::Index> kept;
      for (Eigen::Index i = gram.rows() - 1; i >= 0 && static_cast<int64_t>(kept.size()) < room - V.cols(); --i)
        if (e.eigenvalues()[i] > 1e-26 * scale) kept.push_back(i);
      MatrixXd S(gram.rows(), static_cast<Eigen::Index>(kept.size()));
      for (size_t j = 0; j < kept.size(); ++j)
        S.col(j) = e.eigenvectors().col(kept[j]) / std::sqrt(e.eigenvalues()[kept[j]]);
      Z = product(Z, S);
      MZ = product(MZ, S);
      // Directions scaled up from below 1e-8 of the largest carry M Z's rounding amplified past what
      // the update of pass 1 may keep (the same decision on every rank: the Gram matrix is global).
      freshProduct = !kept.empty() && e.eigenvalues()[kept.back()] < 1e-16 * e.eigenvalues()[kept.front()];
    }
    return coefficients;
  }
};

// -log_view rows for the iteration's own work (the solves and M products have PETSc's).
struct LogEvents {
  PetscLogEvent orthogonalize = registerLogEvent("Block eigensolver", "BlkEigOrthog");
  PetscLogEvent rayleighRitz = registerLogEvent("Block eigensolver", "BlkEigRitz");
};

} // namespace

BlockEigenPairs blockEigenpairs(const DirectSolver& shiftedInverse, Mat mass, double shift,
                                const MatrixXd& deflation, const DofLayout& layout, const BlockEigenSettings& settings) {
  static const LogEvents events;
  const int64_t room = layout.globalDofs() - deflation.cols();
  const int k = settings.count;
  if (k < 1 || k >= room)
    throw std::invalid_argument("cannot compute " + std::to_string(k) + " eigenpairs in a space of " +
                                std::to_string(room) + " dimensions");
  // Each solve streams the whole factor (about 45 ms on the 97k-tet torus of bench/torus_bake.py)
  // and then costs about 5 ms a column; larger blocks need more columns. There, at k = 20 on one
  // rank with the basis room below: blocks of 4, 8, 12, 16 took 124, 172, 224, 260 columns and
  // 3.8, 3.8, 4.1, 4.5 s; on two ranks, which share each block's columns, 8 took 3.1 s and 16 3.3 s.
  const int b = settings.blockSize > 0 ? settings.blockSize : std::min(std::max(k, 4), 8);
  // The basis grows to `cap` columns, then restarts from its best k + b Ritz vectors; then Z (at
  // most b columns, M-orthogonal to the basis it came from) always fits beside what is kept. On the
  // torus (k = 20, b = 8) room for k + 32 columns took 228 solves, k + 64 196, k + 128 172 (one
  // restart); the room costs memory, n (cap + b) doubles twice, more than time.
  const int64_t asked = settings.basisColumns > 0 ? std::max(settings.basisColumns, k + 2 * b) : k + std::max(4 * b, 128);
  const Eigen::Index cap = static_cast<Eigen::Index>(std::min<int64_t>(room, asked));
  const int64_t maxColumns = 200 * static_cast<int64_t>(k + b);
  const Eigen::Index n = layout.localDofs();

  const MatrixXd massDeflation = deflation.cols() > 0 ? multiply(mass, deflation, layout) : MatrixXd(n, 0);
  const Orthonormalizer orthonormalize{deflation, massDeflation, mass, layout, room};
  MatrixXd V(n, cap + b), MV(n, cap + b), T = MatrixXd::Zero(cap + b, cap + b);
  Eigen::Index m = 0, last = 0;  // basis columns; the last block's
  BlockEigenPairs out;
  uint64_t seed = 0;
  auto append = [&](const MatrixXd& Z, const MatrixXd& MZ) {
    V.middleCols(m, Z.cols()) = Z;
    MV.middleCols(m, Z.cols()) = MZ;
    m += Z.cols();
    last = Z.cols();
  };
  auto randomBlock = [&](MatrixXd& Z, MatrixXd& MZ) {
    Z.resize(n, b);
    for (Eigen::Index j = 0; j < b; ++j)
      for (Eigen::Index i = 0; i < n; ++i)
        Z(i, j) = startEntry(3 * static_cast<uint64_t>(layout.ownedVertices()[i / 3]) + i % 3, j, seed);
    ++seed;
    orthonormalize(V.leftCols(m), MV.leftCols(m), Z, MZ, nullptr);
  };
  MatrixXd Z, MZ;
  randomBlock(Z, MZ);
  append(Z, MZ);
  while (true) {
    // The next Krylov block and the Rayleigh quotient T = V^T M (K - sigma M)^-1 M V's new columns.
    Z = shiftedInverse.solve(MV.middleCols(m - last, last));
    out.solvedColumns += static_cast<int>(last);
    MatrixXd residualGram;  // of what the last block's image leaves outside the basis
    MatrixXd c;
    {
      const LogEventScope timed(events.orthogonalize);
      c = orthonormalize(V.leftCols(m), MV.leftCols(m), Z, MZ, &residualGram);
    }
    std::optional<LogEventScope> ritzTimed(std::in_place, events.rayleighRitz);
    T.block(0, m - last, m, last) = c;
    T.block(m - last, 0, last, m) = c.transpose();
    T.block(m - last, m - last, last, last) = 0.5 * (c.bottomRows(last) + c.bottomRows(last).transpose());

    const Eigen::SelfAdjointEigenSolver<MatrixXd> ritz(T.topLeftCorner(m, m));
    // Ritz pair i (largest theta first): its residual is the last block's leftover times y's last
    // rows, measured against the largest theta (the operator's norm): relative to its own theta
    // the solves' rounding sets a floor that grows with lambda_i / lambda_1 (1e-9 at mode 20 of a
    // slender beam).
    const double largest = ritz.eigenvalues()[m - 1];
    int converged = 0;
    for (int i = 0; i < std::min<Eigen::Index>(k, m); ++i) {
      const Eigen::Index col = m - 1 - i;
      const Eigen::VectorXd yLast = ritz.eigenvectors().col(col).tail(last);
      const double residual = std::sqrt(std::max(0.0, yLast.dot(residualGram * yLast)));
      if (ritz.eigenvalues()[col] > 0 && residual <= settings.tolerance * largest) ++converged;
    }
    if (settings.progress) settings.progress(converged, k);
    ritzTimed.reset();
    if (converged == k) {
      // Purified Ritz vectors x = (K - sigma M)^-1 M (V y) / theta, as SLEPc's: the residual V y
      // leaves lies along the stiff modes, which K multiplies by their large eigenvalues; one
      // more solve damps it by theta_stiff / theta.
      const MatrixXd Y = ritz.eigenvectors().rightCols(k).rowwise().reverse();
      const Eigen::VectorXd theta = ritz.eigenvalues().tail(k).reverse();
      out.vectors = shiftedInverse.solve(product(MV.leftCols(m), Y)) * theta.cwiseInverse().asDiagonal();
      out.solvedColumns += k;
      for (int i = 0; i < k; ++i) out.values.push_back(shift + 1 / theta[i]);
      return out;
    }
    if (out.solvedColumns > maxColumns || last == 0)
      throw std::runtime_error("the block eigensolver found " + std::to_string(converged) + " of the " +
                               std::to_string(k) + " eigenpairs requested after " +
                               std::to_string(out.solvedColumns) + " solves");
    if (Z.cols() == 0) randomBlock(Z, MZ);  // the Krylov space closed before k pairs converged
    if (m + Z.cols() > cap) {                // thick restart: the best k + b Ritz vectors
      const Eigen::Index keep = std::min<Eigen::Index>(k + b, m);
      const MatrixXd Y = ritz.eigenvectors().rightCols(keep);
      V.leftCols(keep) = product(V.leftCols(m), Y);
      MV.leftCols(keep) = product(MV.leftCols(m), Y);
      T.topLeftCorner(keep, keep) = ritz.eigenvalues().tail(keep).asDiagonal();
      m = keep;
      ++out.restarts;
    }
    append(Z, MZ);
  }
}

} // namespace quiver
