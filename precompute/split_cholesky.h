#pragma once
// A Cholesky factorization of a distributed symmetric positive definite matrix, split by rank with
// the same bits every run. The interface is the rows that couple to a higher rank's rows (one side
// of each cut, a vertex separator); the other rows of each rank (its interior) couple only to their
// own rank's rows and to the interface. Each rank factors its interior with sequential MUMPS, which
// also forms the interior's Schur complement contribution on the interface rows it touches; the
// interface's Schur complement, summed in rank order, is factored densely on every rank. A solve
// condenses each rank's right-hand sides onto the interface, solves the small dense system there
// and expands back. Each rank holds and streams only its part of the factor: on two ranks, about
// half the memory and half the memory traffic of a whole factor per rank. It pays while the
// interface is small (the dense Schur complement grows as its square), which the partition's small
// edge cut makes it on two or a few ranks.
#include <memory>
#include <vector>

#include <Eigen/Core>
#include <mpi.h>
#include <petscmat.h>

#include "precompute/sequential_cholesky.h"

namespace quiver {

class SplitCholesky {
public:
  // Collective. The split factor of A, or null on every rank when it would not pay: on one rank,
  // when some rank has no interior row, or when the interface has more than `maxInterface` rows.
  // Throws std::runtime_error on every rank when any rank's factorization fails.
  static std::unique_ptr<SplitCholesky> tryCreate(Mat A, MPI_Comm comm, PetscInt maxInterface);

  // X = A^-1 B for `count` columns of this rank's rows (column-major, leading dimension the rank's
  // row count). Collective, with the same `count` on every rank.
  void solve(const double* B, double* X, PetscInt count) const;

  PetscInt interfaceRows() const { return static_cast<PetscInt>(schur_.rows()); }

private:
  SplitCholesky() = default;
  MPI_Comm comm_ = MPI_COMM_NULL;
  int rank_ = 0;
  std::vector<PetscInt> position_;  // owned row -> its interior row (>= 0) or -1 - its interface index
  PetscInt interior_ = 0;
  std::vector<int> interfaceCounts_, interfaceOffsets_;  // each rank's interface rows (contiguous, in rank order)
  std::vector<std::vector<int>> touched_;  // each rank's Schur variables: interface indices its interior touches
  std::unique_ptr<SequentialCholesky> factor_;
  Eigen::MatrixXd schur_;  // the interface's Schur complement's Cholesky factor L, in its lower triangle
};

} // namespace quiver
