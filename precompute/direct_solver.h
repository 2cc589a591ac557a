#pragma once
// A Cholesky factorization of a distributed symmetric positive definite matrix that solves blocks
// of right-hand sides with the same bits every run (issue #16). Parallel MUMPS would give bits that
// change from run to run (it schedules its work as messages arrive) and SuperLU_DIST's
// multi-right-hand-side solve corrupts its heap in Debian 12 (pdReDistribute_B_to_X). So:
// - one rank: a SequentialCholesky of the matrix;
// - several: a SplitCholesky (each rank factors its own interior, the interface between ranks is a
//   dense Schur complement), when every rank has interior rows and the interface has at most
//   -factor_max_interface rows (default 6000: a 288 MB Schur complement per rank);
// - else every rank factors the whole matrix alone and solves its share of the columns (a copy of
//   the matrix and its factor per rank).
// Their bits depend on the inputs and the rank count only. -factor_distributed goes back to one
// distributed factorization through PETSc (bits that may change; -factor_pc_* applies there).
// Options: -factor_mat_mumps_*, -factor_max_interface, -factor_distributed.
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <petscksp.h>

#include "precompute/dof_layout.h"
#include "precompute/petsc_handle.h"
#include "precompute/progress_meter.h"
#include "precompute/sequential_cholesky.h"
#include "precompute/split_cholesky.h"
#include "precompute/stages/assemble.h"

namespace quiver {

class DirectSolver {
public:
  // Factors A now (collective); A must outlive the solver. Throws std::runtime_error when it fails.
  DirectSolver(Mat A, const DofLayout& layout);
  ~DirectSolver();

  // X with A X = B (this rank's rows of both), at most `round` columns per factor solve, progress
  // after each round. Collective; a failure on any rank throws on every rank.
  Eigen::MatrixXd solve(const Eigen::MatrixXd& B, Eigen::Index round = 32,
                        const ProgressCallback& progress = ProgressCallback()) const;

private:
  using PetscKsp = PetscHandle<KSP, KSPDestroy>;
  const DofLayout& layout_;
  std::unique_ptr<SplitCholesky> split_;        // several ranks: a factor split by rank, or
  std::unique_ptr<SequentialCholesky> factor_;  // the whole matrix's on each rank (or A's on one rank)
  PetscKsp ksp_;                                // or PETSc's distributed one (-factor_distributed)
  std::vector<PetscInt> ranges_;  // rows of each rank (PETSc's ownership ranges)
};

// K's factor, made by the first stage that asks for it and kept for the next: the modes of a fixed
// object (shift 0) and its modal derivatives solve with the same K.
class StiffnessFactor {
public:
  StiffnessFactor(Mat stiffness, const DofLayout& layout) : stiffness_(stiffness), layout_(layout) {}
  // Throws, where K is not positive definite, what makes a fixed object's K singular.
  const DirectSolver& get();
  void release() { solver_.reset(); }

private:
  Mat stiffness_;
  const DofLayout& layout_;
  std::unique_ptr<DirectSolver> solver_;
};

} // namespace quiver
