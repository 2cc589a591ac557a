#include "precompute/distributed_dense.h"

#include <cblas.h>

namespace quiver {

PetscMat wrapDenseColumns(Eigen::MatrixXd& local, Eigen::Index first, Eigen::Index count, const DofLayout& layout) {
  PetscMat D;
  QV_PETSC(MatCreateDense(layout.comm(), layout.localDofs(), PETSC_DECIDE, layout.globalDofs(),
                          static_cast<PetscInt>(count), local.data() + first * local.rows(), D.out()));
  return D;
}

PetscMat wrapDense(Eigen::MatrixXd& local, const DofLayout& layout) {
  return wrapDenseColumns(local, 0, local.cols(), layout);
}

Eigen::MatrixXd multiply(Mat A, const Eigen::MatrixXd& X, const DofLayout& layout) {
  Eigen::MatrixXd input = X;  // PETSc wants a writable array even for a read-only operand
  PetscMat D = wrapDense(input, layout);
  PetscMat product;
  QV_PETSC(MatMatMult(A, D, MAT_INITIAL_MATRIX, PETSC_DEFAULT, product.out()));
  return localRows(product, layout);
}

Eigen::MatrixXd localRows(Mat dense, const DofLayout& layout) {
  PetscInt lda = 0, cols = 0;
  const PetscScalar* values = nullptr;
  QV_PETSC(MatGetSize(dense, nullptr, &cols));
  QV_PETSC(MatDenseGetLDA(dense, &lda));
  QV_PETSC(MatDenseGetArrayRead(dense, &values));
  Eigen::MatrixXd out = Eigen::Map<const Eigen::MatrixXd, 0, Eigen::OuterStride<>>(values, layout.localDofs(), cols,
                                                                                  Eigen::OuterStride<>(lda));
  QV_PETSC(MatDenseRestoreArrayRead(dense, &values));
  return out;
}

void multiplyInto(Eigen::Ref<const Eigen::MatrixXd> A, bool transposeA, Eigen::Ref<const Eigen::MatrixXd> B, double alpha,
                  double beta, Eigen::Ref<Eigen::MatrixXd> C) {
  const Eigen::Index inner = transposeA ? A.rows() : A.cols();
  if (C.size() == 0) return;
  if (inner == 0) {  // a rank without rows: its part of a product is zero (C may be uninitialised)
    if (beta == 0)
      C.setZero();
    else
      C *= beta;
    return;
  }
  cblas_dgemm(CblasColMajor, transposeA ? CblasTrans : CblasNoTrans, CblasNoTrans, static_cast<int>(C.rows()),
              static_cast<int>(C.cols()), static_cast<int>(inner), alpha, A.data(), static_cast<int>(A.outerStride()),
              B.data(), static_cast<int>(B.outerStride()), beta, C.data(), static_cast<int>(C.outerStride()));
}

Eigen::MatrixXd innerProducts(Eigen::Ref<const Eigen::MatrixXd> X, Eigen::Ref<const Eigen::MatrixXd> Y, MPI_Comm comm) {
  Eigen::MatrixXd mine(X.cols(), Y.cols()), total(X.cols(), Y.cols());
  multiplyInto(X, true, Y, 1.0, 0.0, mine);
  MPI_Allreduce(mine.data(), total.data(), static_cast<int>(mine.size()), MPI_DOUBLE, MPI_SUM, comm);
  return total;
}

Eigen::VectorXd columnNorms(const Eigen::MatrixXd& X, MPI_Comm comm) {
  Eigen::VectorXd mine = X.colwise().squaredNorm().transpose(), total(mine.size());
  MPI_Allreduce(mine.data(), total.data(), static_cast<int>(mine.size()), MPI_DOUBLE, MPI_SUM, comm);
  return total.cwiseSqrt();
}

} // namespace quiver
