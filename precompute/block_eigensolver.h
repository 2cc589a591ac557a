#pragma once
// The eigenpairs of K x = lambda M x nearest a shift sigma below them, by a block Krylov-Schur
// iteration with shift-and-invert: Rayleigh-Ritz on a block Krylov space of (K - sigma M)^-1 M,
// M-orthonormal, thick restarts keeping the best Ritz vectors. It exists for one reason: blocks.
// A triangular solve with one right-hand side streams the whole factor for little arithmetic; in
// blocks each column costs far less (on a 97k-tet torus: 45 ms for one, about 8 ms a column in
// blocks of eight), and SLEPc's Krylov-Schur solves one vector at a time. SLEPc's LOBPCG, which calls the
// blocked solve, broke down in its Gram matrix (DSSolve_GHEP) on that torus; Trilinos' Anasazi
// BlockKrylovSchur (Debian has it) needed 260-1200 solves there and an M product per
// orthogonalisation, no faster than SLEPc. SLEPc's Krylov-Schur stays available
// (--eigensolver krylov-schur) and is the second solver the tests hold this one to.
#include <vector>

#include <Eigen/Core>
#include <petscmat.h>

#include "precompute/direct_solver.h"
#include "precompute/dof_layout.h"
#include "precompute/progress_meter.h"

namespace quiver {

struct BlockEigenSettings {
  int count = 20;            // eigenpairs wanted
  double tolerance = 1e-12;  // ||(K - sigma M)^-1 M x - theta x||_M / theta_1, x M-normalised, theta = 1 / (lambda - sigma)
  int blockSize = 0;         // 0: min(max(count, 4), 8); -modes_block_size in the bake
  int basisColumns = 0;      // the basis's room before a thick restart; 0: count + max(4 blockSize, 128)
  ProgressCallback progress; // (converged, count)
};

struct BlockEigenPairs {
  std::vector<double> values;  // ascending
  Eigen::MatrixXd vectors;     // this rank's rows, M-orthonormal
  int solvedColumns = 0;       // right-hand sides solved
  int restarts = 0;            // thick restarts made
};

// `shiftedInverse` solves with K - shift M, which must be positive definite (it is a Cholesky
// factor); the iteration stays M-orthogonal to `deflation` (this rank's rows of M-orthonormal
// columns, e.g. the rigid modes, or none). The starting block is pseudo-random by vertex: the same bits every run, the same start on
// any rank count. Collective.
// Throws std::runtime_error when it does not converge.
BlockEigenPairs blockEigenpairs(const DirectSolver& shiftedInverse, Mat mass, double shift,
                                const Eigen::MatrixXd& deflation, const DofLayout& layout,
                                const BlockEigenSettings& settings);

} // namespace quiver
