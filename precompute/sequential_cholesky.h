#pragma once
// A sparse Cholesky factorization of a symmetric positive definite matrix on this rank, optionally
// leaving out a set of variables whose Schur complement it forms (DirectSolver splits a matrix
// between ranks that way), or factored anew with new values (the fidelity stage's Newton
// systems): MUMPS called directly (sequential, on MPI_COMM_SELF) in a METIS
// nested-dissection order of the matrix's vertex graph (blocks of three DOFs). Debian's MUMPS has
// no METIS of its own and falls back to PORD: on the 97k-tet torus of bench/torus_bake.py the METIS
// order has 12% fewer factor entries and 28% fewer flops (order and factor 1.22 s against 1.37 s
// through PETSc). Sequential MUMPS gives the same bits every run.
//
// Options (PETSc's database, prefix "factor_", named as PETSc's own MUMPS interface names them):
// -factor_mat_mumps_icntl_<i> and -factor_mat_mumps_cntl_<i>; -factor_mat_mumps_icntl_7 chooses
// one of MUMPS's own orderings instead of METIS.
#include <memory>
#include <stdexcept>
#include <vector>

#include <Eigen/Core>
#include <petscmat.h>

namespace quiver {

// What SequentialCholesky throws when the matrix has negative or zero pivots.
struct NotPositiveDefinite : std::runtime_error {
  using std::runtime_error::runtime_error;
};

class SequentialCholesky {
public:
  // A symmetric matrix by its upper triangle, 0-based (i <= j), n rows.
  struct UpperTriangle {
    PetscInt n = 0;
    std::vector<int> rows, cols;
    std::vector<double> values;
  };
  // A's upper triangle; every row of A on this rank (a sequential matrix, or a parallel one on one rank).
  static UpperTriangle upperTriangle(Mat A);

  // Factors the matrix, whose last `schurSize` variables stay out of the factor: for
  // [A_II A_IS; A_SI A_SS] it factors A_II and forms the Schur complement A_SS - A_SI A_II^-1 A_IS
  // (takeSchurComplement()). Throws std::runtime_error naming MUMPS's error, or NotPositiveDefinite
  // when the matrix (A_II) is not positive definite (negative pivots, counted, or a zero one).
  // `refactorable` keeps the pattern (its rows and columns) for refactor().
  explicit SequentialCholesky(UpperTriangle upper, PetscInt schurSize = 0, bool refactorable = false);
  ~SequentialCholesky();
  SequentialCholesky(const SequentialCholesky&) = delete;
  SequentialCholesky& operator=(const SequentialCholesky&) = delete;

  // Factors a matrix of the same pattern anew: `values` in the order of the UpperTriangle's entries,
  // with the order and analysis of the first (Newton's Hessians change their values only). Throws
  // as the constructor does; after a throw, refactor() may be called again, but nothing solves
  // until one succeeds.
  void refactor(const std::vector<double>& values);

  // Without Schur variables: overwrites `columns` (column-major, rows() rows) with A^-1 columns.
  void solveInPlace(double* columns, PetscInt count) const;
  // With them, in two steps around the caller's solve of the Schur system: condense() leaves in
  // `reduced` (schurSize rows) b_S - A_SI A_II^-1 b_I; given x_S, expand() overwrites `columns`
  // with the whole solution. `columns` must come to expand() as condense() left it.
  void condense(double* columns, PetscInt count, double* reduced) const;
  void expand(double* columns, PetscInt count, const double* schurSolution) const;
  // The Schur complement, dense and symmetric (schurSize square); empty once taken.
  Eigen::MatrixXd takeSchurComplement();

  PetscInt rows() const { return rows_; }
  // The order MUMPS factored in (its INFOG(7)): 1, ours; else its own, as -factor_mat_mumps_icntl_7 chose.
  int orderingUsed() const;

private:
  struct Mumps;
  void factor();
  void solvePhase(double* columns, PetscInt count, int condensation, double* reduced) const;
  std::unique_ptr<Mumps> mumps_;
  PetscInt rows_ = 0, schurSize_ = 0;
  bool refactorable_ = false, factored_ = false;
};

} // namespace quiver
