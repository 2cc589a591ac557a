#include "precompute/split_cholesky.h"

#include <algorithm>
#include <climits>
#include <stdexcept>
#include <string>

#include <Eigen/Cholesky>

#include "precompute/bake_context.h"
#include "precompute/petsc_handle.h"

namespace quiver {

namespace {

template <class T> MPI_Datatype mpiType();
template <> MPI_Datatype mpiType<double>() { return MPI_DOUBLE; }
template <> MPI_Datatype mpiType<int>() { return MPI_INT; }

// MPI_Allgatherv of `mine` with every rank's count into `all`; the blocks land in rank order.
template <class T>
void gatherInRankOrder(const T* mine, const std::vector<long long>& counts, T* all, MPI_Comm comm) {
  std::vector<int> c(counts.size()), offsets(counts.size());
  long long total = 0;
  for (size_t p = 0; p < counts.size(); ++p) {
    if (total + counts[p] > INT_MAX) throw std::runtime_error("split Cholesky: a gather too large for one MPI call");
    offsets[p] = static_cast<int>(total);
    c[p] = static_cast<int>(counts[p]);
    total += counts[p];
  }
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  MPI_Allgatherv(mine, c[rank], mpiType<T>(), all, c.data(), offsets.data(), mpiType<T>(), comm);
}

template <class T>
std::vector<T> gatherInRankOrder(const T* mine, const std::vector<long long>& counts, MPI_Comm comm) {
  long long total = 0;
  for (long long c : counts) total += c;
  std::vector<T> all(static_cast<size_t>(std::max(total, 0LL)));
  gatherInRankOrder(mine, counts, all.data(), comm);
  return all;
}

} // namespace

std::unique_ptr<SplitCholesky> SplitCholesky::tryCreate(Mat A, MPI_Comm comm, PetscInt maxInterface) {
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  if (size == 1) return nullptr;
  PetscInt start = 0, end = 0;
  QV_PETSC(MatGetOwnershipRange(A, &start, &end));
  const PetscInt owned = end - start;
  auto forEachRow = [&](auto&& visit) {  // visit(row, columns, values, length)
    for (PetscInt i = start; i < end; ++i) {
      PetscInt length = 0;
      const PetscInt* cols = nullptr;
      const PetscScalar* values = nullptr;
      QV_PETSC(MatGetRow(A, i, &length, &cols, &values));
      visit(i, cols, values, length);
      QV_PETSC(MatRestoreRow(A, i, &length, &cols, &values));
    }
  };

  // Interface rows: those with a column a higher rank owns (A is symmetric: the higher rank's rows
  // then couple back to them, and two ranks' interior rows never couple).
  std::unique_ptr<SplitCholesky> split(new SplitCholesky());
  SplitCholesky& s = *split;
  s.comm_ = comm;
  s.rank_ = rank;
  s.position_.resize(static_cast<size_t>(owned));
  std::vector<double> mineRows;  // this rank's interface rows (global numbers; exact below 2^53)
  forEachRow([&](PetscInt i, const PetscInt* cols, const PetscScalar*, PetscInt length) {
    const bool border = std::any_of(cols, cols + length, [&](PetscInt j) { return j >= end; });
    s.position_[i - start] = border ? -1 - static_cast<PetscInt>(mineRows.size()) : s.interior_++;
    if (border) mineRows.push_back(static_cast<double>(i));
  });
  const int mine = static_cast<int>(std::min<size_t>(mineRows.size(), INT_MAX));
  s.interfaceCounts_.resize(size);
  MPI_Allgather(&mine, 1, MPI_INT, s.interfaceCounts_.data(), 1, MPI_INT, comm);
  long long total = 0;
  for (int p = 0; p < size; ++p) {
    s.interfaceOffsets_.push_back(static_cast<int>(std::min<long long>(total, INT_MAX)));
    total += s.interfaceCounts_[p];
  }
  long long fewestInterior = s.interior_;
  MPI_Allreduce(MPI_IN_PLACE, &fewestInterior, 1, MPI_LONG_LONG, MPI_MIN, comm);
  if (fewestInterior == 0 || total > maxInterface) return nullptr;
  const std::vector<long long> counts(s.interfaceCounts_.begin(), s.interfaceCounts_.end());
  const std::vector<double> interfaceRows = gatherInRankOrder(mineRows.data(), counts, comm);
  // Its index in the interface, or -1 (a column that is no interface row).
  auto interfaceIndex = [&](PetscInt j) {
    const auto at = std::lower_bound(interfaceRows.begin(), interfaceRows.end(), static_cast<double>(j));
    return at != interfaceRows.end() && *at == static_cast<double>(j) ? static_cast<int>(at - interfaceRows.begin()) : -1;
  };

  // The interface indices this rank's interior touches (its Schur variables), then the local
  // matrix: interior rows first, those after; its Schur block is left empty (zero), so that MUMPS
  // returns the interior's contribution -A_SI A_II^-1 A_IS alone. The interface rows' own entries
  // go straight into this rank's rows of the whole Schur complement.
  // An interior row's column of another rank is an interface row when A's pattern is symmetric.
  std::vector<int> touched;
  std::string failure;
  forEachRow([&](PetscInt i, const PetscInt* cols, const PetscScalar*, PetscInt length) {
    if (s.position_[i - start] < 0) return;
    for (PetscInt e = 0; e < length; ++e)
      if (cols[e] < start || s.position_[cols[e] - start] < 0) {
        const int k = interfaceIndex(cols[e]);
        if (k < 0 && failure.empty())
          failure = "split Cholesky: the matrix is not structurally symmetric (row " + std::to_string(i) +
                    " has column " + std::to_string(cols[e]) + ", whose row has no column " + std::to_string(i) + ")";
        if (k >= 0) touched.push_back(k);
      }
  });
  throwIfAnyRankFailed(failure, comm);
  std::sort(touched.begin(), touched.end());
  touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
  SequentialCholesky::UpperTriangle upper;
  upper.n = s.interior_ + static_cast<PetscInt>(touched.size());
  Eigen::MatrixXd schurRows = Eigen::MatrixXd::Zero(mine, static_cast<Eigen::Index>(total));
  forEachRow([&](PetscInt i, const PetscInt* cols, const PetscScalar* values, PetscInt length) {
    const PetscInt li = s.position_[i - start];
    for (PetscInt e = 0; e < length; ++e) {
      const bool ownInterior = cols[e] >= start && cols[e] < end && s.position_[cols[e] - start] >= 0;
      if (li < 0) {  // an interface row: its entries in interface columns (the others are interior rows')
        const int k = interfaceIndex(cols[e]);
        if (!ownInterior && k >= 0) schurRows(-1 - li, k) = values[e];
        continue;
      }
      PetscInt lj = 0;
      if (ownInterior) {
        lj = s.position_[cols[e] - start];
        if (lj < li) continue;
      } else {
        lj = s.interior_ + (std::lower_bound(touched.begin(), touched.end(), interfaceIndex(cols[e])) - touched.begin());
      }
      upper.rows.push_back(static_cast<int>(li));
      upper.cols.push_back(static_cast<int>(lj));
      upper.values.push_back(values[e]);
    }
  });
  // Every rank's Schur variables, so that every rank can add every contribution.
  std::vector<long long> touchedCounts(size);
  const long long mineTouched = static_cast<long long>(touched.size());
  MPI_Allgather(&mineTouched, 1, MPI_LONG_LONG, touchedCounts.data(), 1, MPI_LONG_LONG, comm);
  const std::vector<int> allTouched = gatherInRankOrder(touched.data(), touchedCounts, comm);
  for (int p = 0, offset = 0; p < size; offset += static_cast<int>(touchedCounts[p]), ++p)
    s.touched_.emplace_back(allTouched.begin() + offset, allTouched.begin() + offset + touchedCounts[p]);

  Eigen::MatrixXd contribution;
  try {
    s.factor_ = std::make_unique<SequentialCholesky>(std::move(upper), static_cast<PetscInt>(touched.size()));
    contribution = s.factor_->takeSchurComplement();
  } catch (const std::exception& e) {
    failure = e.what();
  }
  throwIfAnyRankFailed(failure, comm);

  // The whole Schur complement on every rank: the interface rows' own entries (each rank's rows,
  // transposed into columns of the symmetric whole), plus every rank's contribution in rank order.
  {
    static const PetscLogEvent event = registerLogEvent("Split Cholesky", "SplitSchurFactor");  // a -log_view row
    const LogEventScope timed(event);
    const Eigen::MatrixXd transposed = schurRows.transpose();
    std::vector<long long> rowCounts = counts, contributionCounts(size);
    for (int p = 0; p < size; ++p) {
      rowCounts[p] *= total;
      contributionCounts[p] = touchedCounts[p] * touchedCounts[p];
    }
    s.schur_.resize(total, total);
    gatherInRankOrder(transposed.data(), rowCounts, s.schur_.data(), comm);
    const std::vector<double> contributions = gatherInRankOrder(contribution.data(), contributionCounts, comm);
    for (int p = 0, offset = 0; p < size; offset += static_cast<int>(contributionCounts[p]), ++p) {
      const auto& t = s.touched_[p];
      const Eigen::Map<const Eigen::MatrixXd> c(contributions.data() + offset, t.size(), t.size());
      for (size_t b = 0; b < t.size(); ++b)
        for (size_t a = 0; a < t.size(); ++a) s.schur_(t[a], t[b]) += c(a, b);
    }
    // In place: the lower triangle becomes L (S = L L^T), no second dense copy.
    const Eigen::LLT<Eigen::Ref<Eigen::MatrixXd>> factor(s.schur_);
    if (factor.info() != Eigen::Success)
      throw std::runtime_error("the matrix to factor is not positive definite (its Schur complement on the " +
                               std::to_string(total) + " rows between ranks is not)");
  }
  return split;
}

void SplitCholesky::solve(const double* B, double* X, PetscInt count) const {
  if (count <= 0) return;
  const PetscInt owned = static_cast<PetscInt>(position_.size());
  const int size = static_cast<int>(interfaceCounts_.size());
  const std::vector<int>& touched = touched_[rank_];
  const Eigen::Index schurVariables = static_cast<Eigen::Index>(touched.size());
  // Interior right-hand sides, zero on the Schur variables; this rank's interface rows apart.
  Eigen::MatrixXd local = Eigen::MatrixXd::Zero(interior_ + schurVariables, count);
  Eigen::MatrixXd border(interfaceCounts_[rank_], count), reduced(schurVariables, count);
  for (PetscInt c = 0; c < count; ++c)
    for (PetscInt i = 0; i < owned; ++i) {
      const PetscInt at = position_[i];
      (at >= 0 ? local(at, c) : border(-1 - at, c)) = B[c * owned + i];
    }
  std::string failure;
  try {
    if (schurVariables > 0) factor_->condense(local.data(), count, reduced.data());
  } catch (const std::exception& e) {
    failure = e.what();
  }
  throwIfAnyRankFailed(failure, comm_);

  // g = b_S + the contributions -A_SI A_II^-1 b_I, added in rank order; then x_S on every rank.
  Eigen::MatrixXd xS;
  {
    static const PetscLogEvent event = registerLogEvent("Split Cholesky", "SplitSchurSolve");  // a -log_view row
    const LogEventScope timed(event);
    std::vector<long long> borderCounts(size), reducedCounts(size);
    for (int p = 0; p < size; ++p) {
      borderCounts[p] = static_cast<long long>(interfaceCounts_[p]) * count;
      reducedCounts[p] = static_cast<long long>(touched_[p].size()) * count;
    }
    const std::vector<double> borders = gatherInRankOrder(border.data(), borderCounts, comm_);
    const std::vector<double> contributions = gatherInRankOrder(reduced.data(), reducedCounts, comm_);
    Eigen::MatrixXd g(schur_.rows(), count);
    for (int p = 0, offset = 0; p < size; offset += static_cast<int>(borderCounts[p]), ++p)
      g.middleRows(interfaceOffsets_[p], interfaceCounts_[p]) =
          Eigen::Map<const Eigen::MatrixXd>(borders.data() + offset, interfaceCounts_[p], count);
    for (int p = 0, offset = 0; p < size; offset += static_cast<int>(reducedCounts[p]), ++p) {
      const Eigen::Map<const Eigen::MatrixXd> c(contributions.data() + offset, touched_[p].size(), count);
      for (Eigen::Index k = 0; k < c.rows(); ++k) g.row(touched_[p][k]) += c.row(k);
    }
    const auto L = schur_.triangularView<Eigen::Lower>();
    L.solveInPlace(g);
    L.transpose().solveInPlace(g);
    xS = std::move(g);
  }
  Eigen::MatrixXd mineSolution(schurVariables, count);
  for (Eigen::Index k = 0; k < schurVariables; ++k) mineSolution.row(k) = xS.row(touched[k]);
  try {
    if (schurVariables > 0)
      factor_->expand(local.data(), count, mineSolution.data());
    else  // an interior coupled to no interface: it solves alone
      factor_->solveInPlace(local.data(), count);
  } catch (const std::exception& e) {
    failure = e.what();
  }
  throwIfAnyRankFailed(failure, comm_);
  for (PetscInt c = 0; c < count; ++c)
    for (PetscInt i = 0; i < owned; ++i) {
      const PetscInt at = position_[i];
      X[c * owned + i] = at >= 0 ? local(at, c) : xS(interfaceOffsets_[rank_] - 1 - at, c);
    }
}

} // namespace quiver
