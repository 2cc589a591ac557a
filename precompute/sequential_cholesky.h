#pragma once
// A sparse Cholesky factorization of a symmetric positive definite matrix held whole on this rank:
// MUMPS called directly (sequential, on MPI_COMM_SELF) in a METIS nested-dissection order of the
// matrix's vertex graph (blocks of three DOFs). Debian's MUMPS has no METIS of its own and falls
// back to PORD: on the 97k-tet torus of bench/torus_bake.py the METIS order has 12% fewer factor
// entries and 28% fewer flops, and calling MUMPS without PETSc's wrapper saves about a fifth of
// each solve. Sequential MUMPS gives the same bits every run.
//
// Options (PETSc's database, prefix "factor_", named as PETSc's own MUMPS interface names them):
// -factor_mat_mumps_icntl_<i> and -factor_mat_mumps_cntl_<i>; -factor_mat_mumps_icntl_7 chooses
// one of MUMPS's own orderings instead of METIS.
#include <memory>
#include <vector>

#include <petscmat.h>

namespace quiver {

class SequentialCholesky {
public:
  // Factors A (every row on this rank: a sequential matrix, or a parallel one on one rank). Throws
  // std::runtime_error naming MUMPS's error, or the count of negative pivots when A is not
  // positive definite.
  explicit SequentialCholesky(Mat A);
  ~SequentialCholesky();
  SequentialCholesky(const SequentialCholesky&) = delete;
  SequentialCholesky& operator=(const SequentialCholesky&) = delete;

  // Overwrites `columns` (column-major, rows() rows) with A^-1 columns.
  void solveInPlace(double* columns, PetscInt count) const;
  PetscInt rows() const { return rows_; }
  // The order MUMPS factored in (its INFOG(7)): 1, ours; else its own, as -factor_mat_mumps_icntl_7 chose.
  int orderingUsed() const;

private:
  struct Mumps;
  std::unique_ptr<Mumps> mumps_;
  PetscInt rows_ = 0;
};

} // namespace quiver
