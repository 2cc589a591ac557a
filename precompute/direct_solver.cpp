#include "precompute/direct_solver.h"

#include <algorithm>
#include <climits>
#include <stdexcept>

#include "precompute/bake_context.h"
#include "precompute/distributed_dense.h"

namespace quiver {

namespace {

// MPI_Alltoallv of doubles; the counts (per rank) must fit MPI's int, which solve()'s rounds do.
std::vector<double> exchange(const std::vector<double>& send, const std::vector<size_t>& sendCounts,
                             const std::vector<size_t>& receiveCounts, MPI_Comm comm) {
  const size_t size = sendCounts.size();
  std::vector<int> sc(size), so(size), rc(size), ro(size);
  size_t sent = 0, received = 0;
  for (size_t p = 0; p < size; ++p) {
    if (sent + sendCounts[p] > INT_MAX || received + receiveCounts[p] > INT_MAX)
      throw std::runtime_error("direct solver: a block of right-hand sides is too large for one MPI exchange");
    so[p] = static_cast<int>(sent);
    sc[p] = static_cast<int>(sendCounts[p]);
    ro[p] = static_cast<int>(received);
    rc[p] = static_cast<int>(receiveCounts[p]);
    sent += sendCounts[p];
    received += receiveCounts[p];
  }
  std::vector<double> receive(received);
  MPI_Alltoallv(send.data(), sc.data(), so.data(), MPI_DOUBLE, receive.data(), rc.data(), ro.data(), MPI_DOUBLE, comm);
  return receive;
}

} // namespace

DirectSolver::DirectSolver(Mat A, const DofLayout& layout) : layout_(layout) {
  int size = 1;
  MPI_Comm_size(layout.comm(), &size);
  PetscBool distributed = PETSC_FALSE;
  QV_PETSC(PetscOptionsGetBool(nullptr, "factor_", "-distributed", &distributed, nullptr));
  const PetscInt* ranges = nullptr;
  QV_PETSC(MatGetOwnershipRanges(A, &ranges));
  ranges_.assign(ranges, ranges + size + 1);
  if (distributed) {  // collective calls: every rank throws alike
    PC pc;
    QV_PETSC(KSPCreate(layout.comm(), ksp_.out()));
    QV_PETSC(KSPSetOptionsPrefix(ksp_, "factor_"));
    QV_PETSC(KSPSetOperators(ksp_, A, A));
    QV_PETSC(KSPSetType(ksp_, KSPPREONLY));
    QV_PETSC(KSPGetPC(ksp_, &pc));
    QV_PETSC(PCSetType(pc, PCCHOLESKY));
    QV_PETSC(PCFactorSetMatSolverType(pc, MATSOLVERMUMPS));
    QV_PETSC(KSPSetFromOptions(ksp_));
    // A failed factorization (MUMPS out of memory, a singular K) only marks the factor in PETSc
    // 3.18; solves would then return Inf. This makes setup and solves raise instead.
    QV_PETSC(KSPSetErrorIfNotConverged(ksp_, PETSC_TRUE));
    QV_PETSC(KSPSetUp(ksp_));
    return;
  }
  PetscInt maxInterface = 6000;  // a dense Schur complement of 288 MB per rank
  QV_PETSC(PetscOptionsGetInt(nullptr, "factor_", "-max_interface", &maxInterface, nullptr));
  if (maxInterface < 0 || maxInterface > 46340)  // a dense Schur complement gathered in one MPI call of int counts
    throw std::runtime_error("-factor_max_interface " + std::to_string(maxInterface) +
                             ": must lie in 0..46340 (0: every rank factors the whole matrix)");
  split_ = SplitCholesky::tryCreate(A, layout.comm(), maxInterface);
  if (split_) return;
  PetscMat whole;  // several ranks: this rank's copy of the whole matrix, on a communicator of one
  if (size > 1) QV_PETSC(MatCreateRedundantMatrix(A, size, MPI_COMM_NULL, MAT_INITIAL_MATRIX, whole.out()));
  std::string failure;
  try {
    factor_ = std::make_unique<SequentialCholesky>(SequentialCholesky::upperTriangle(size > 1 ? whole.get() : A));
  } catch (const std::exception& e) {
    failure = e.what();
  }
  throwIfAnyRankFailed(failure, layout.comm());
}

DirectSolver::~DirectSolver() = default;

const DirectSolver& StiffnessFactor::get() {
  if (solver_) return *solver_;
  try {
    solver_ = std::make_unique<DirectSolver>(stiffness_, layout_);
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    if (what.rfind("the matrix to factor is not positive definite", 0) != 0) throw;
    // Said in the factor's terms alone ("3 negative pivots"), it left users guessing.
    throw std::runtime_error("the rest stiffness K is singular: the fixed vertices leave the object free to move "
                             "rigidly (fix at least three vertices not on one line, or none for a free object) (" +
                             what + ")");
  }
  return *solver_;
}

Eigen::MatrixXd DirectSolver::solve(const Eigen::MatrixXd& B, Eigen::Index round,
                                    const ProgressCallback& progress) const {
  const Eigen::Index total = B.cols();
  round = std::max<Eigen::Index>(round, 1);
  Eigen::MatrixXd X(B.rows(), total);
  if (split_) {
    for (Eigen::Index first = 0; first < total; first += round) {
      const Eigen::Index count = std::min(round, total - first);
      split_->solve(B.col(first).data(), X.col(first).data(), count);
      if (progress) progress(first + count, total);
    }
    return X;
  }
  if (ksp_.get()) {  // -factor_distributed
    Eigen::MatrixXd b = B;  // PETSc wants writable arrays
    for (Eigen::Index first = 0; first < total; first += round) {
      const Eigen::Index count = std::min(round, total - first);
      PetscMat rhs = wrapDenseColumns(b, first, count, layout_), x = wrapDenseColumns(X, first, count, layout_);
      QV_PETSC(KSPMatSolve(ksp_, rhs, x));
      if (progress) progress(first + count, total);
    }
    return X;
  }

  int rank = 0, size = 1;
  MPI_Comm_rank(layout_.comm(), &rank);
  MPI_Comm_size(layout_.comm(), &size);
  auto rows = [&](int p) { return static_cast<Eigen::Index>(ranges_[p + 1] - ranges_[p]); };
  auto start = [&](int p) { return total * p / size; };  // rank p's columns: [start(p), start(p + 1))
  Eigen::Index most = 0, widest = 0;
  for (int p = 0; p < size; ++p) {
    most = std::max(most, start(p + 1) - start(p));
    widest = std::max(widest, rows(p));
  }
  const Eigen::Index n = layout_.globalDofs();
  // Rounds small enough that every exchange's counts fit MPI's int (the same on every rank).
  round = std::max<Eigen::Index>(1, std::min<Eigen::Index>(round, INT_MAX / std::max(n, widest * size)));
  for (Eigen::Index first = 0; first < most; first += round) {
    // This round: columns [begin(p), begin(p) + count(p)) of each rank p.
    auto begin = [&](int p) { return start(p) + first; };
    auto count = [&](int p) { return std::clamp<Eigen::Index>(start(p + 1) - begin(p), 0, round); };
    const Eigen::Index mine = count(rank);
    // Each rank's rows of my columns, in global row order.
    std::vector<double> send;
    std::vector<size_t> sendCounts(size), receiveCounts(size);
    for (int p = 0; p < size; ++p) {
      if (count(p) > 0) {  // columns of one rank are contiguous in B
        const double* part = B.col(begin(p)).data();
        send.insert(send.end(), part, part + B.rows() * count(p));
      }
      sendCounts[p] = static_cast<size_t>(B.rows() * count(p));
      receiveCounts[p] = static_cast<size_t>(rows(p) * mine);
    }
    std::vector<double> received = exchange(send, sendCounts, receiveCounts, layout_.comm());
    Eigen::MatrixXd x(n, mine);  // the right-hand sides, then the solutions
    for (int p = 0, offset = 0; p < size; offset += static_cast<int>(receiveCounts[p]), ++p)
      x.middleRows(ranges_[p], rows(p)) = Eigen::Map<const Eigen::MatrixXd>(received.data() + offset, rows(p), mine);
    std::string failure;
    try {
      factor_->solveInPlace(x.data(), mine);
    } catch (const std::exception& e) {
      failure = e.what();
    }
    throwIfAnyRankFailed(failure, layout_.comm());
    // And back: each rank gets its rows of my columns.
    send.clear();
    for (int p = 0; p < size; ++p) {
      const Eigen::MatrixXd part = x.middleRows(ranges_[p], rows(p));
      send.insert(send.end(), part.data(), part.data() + part.size());
      sendCounts[p] = static_cast<size_t>(part.size());
      receiveCounts[p] = static_cast<size_t>(B.rows() * count(p));
    }
    received = exchange(send, sendCounts, receiveCounts, layout_.comm());
    for (int p = 0, offset = 0; p < size; offset += static_cast<int>(receiveCounts[p]), ++p)
      if (count(p) > 0)
        X.middleCols(begin(p), count(p)) = Eigen::Map<const Eigen::MatrixXd>(received.data() + offset, B.rows(), count(p));
    if (progress) {
      Eigen::Index solved = 0;
      for (int p = 0; p < size; ++p) solved += std::min(start(p + 1) - start(p), first + round);
      progress(solved, total);
    }
  }
  return X;
}

} // namespace quiver
