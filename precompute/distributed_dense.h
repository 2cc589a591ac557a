#pragma once
// Row-distributed dense blocks (this rank's rows of a tall global matrix, as an Eigen matrix in
// the DofLayout's row order) and the few operations the bake needs on them.
#include <Eigen/Core>
#include <petscmat.h>

#include "precompute/dof_layout.h"
#include "precompute/stages/assemble.h"

namespace quiver {

// A PETSc MPIDENSE matrix that shares `local`'s storage (no copy); `local` must outlive it.
PetscMat wrapDense(Eigen::MatrixXd& local, const DofLayout& layout);
// The same for columns [first, first + count) of `local`.
PetscMat wrapDenseColumns(Eigen::MatrixXd& local, Eigen::Index first, Eigen::Index count, const DofLayout& layout);

// A copy of this rank's rows of a distributed dense matrix (whatever its leading dimension).
Eigen::MatrixXd localRows(Mat dense, const DofLayout& layout);

// This rank's rows of A X, for a distributed sparse A and row-distributed X. Collective.
Eigen::MatrixXd multiply(Mat A, const Eigen::MatrixXd& X, const DofLayout& layout);

// C = alpha op(A) B + beta C (op(A) = A or A^T) on this rank's data, through BLAS: the tall-skinny
// products of the eigensolver and the projections run at OpenBLAS's speed, not portable Eigen's.
void multiplyInto(Eigen::Ref<const Eigen::MatrixXd> A, bool transposeA, Eigen::Ref<const Eigen::MatrixXd> B, double alpha,
                  double beta, Eigen::Ref<Eigen::MatrixXd> C);

// X^T Y summed over all ranks: the same small matrix on every rank. Collective.
Eigen::MatrixXd innerProducts(Eigen::Ref<const Eigen::MatrixXd> X, Eigen::Ref<const Eigen::MatrixXd> Y, MPI_Comm comm);

// Euclidean norm of each global column. Collective.
Eigen::VectorXd columnNorms(const Eigen::MatrixXd& X, MPI_Comm comm);

} // namespace quiver
