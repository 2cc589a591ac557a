// The per-rank Cholesky factor (MUMPS in a METIS order) against Eigen's dense solve, with the
// order MUMPS picks itself, on matrices whose rows are and are not in vertex triples, and its
// refusal of an indefinite matrix.
#include <gtest/gtest.h>

#include <random>

#include <Eigen/Dense>

#include "precompute/petsc_handle.h"
#include "precompute/sequential_cholesky.h"
#include "precompute/stages/assemble.h"  // PetscMat

using namespace quiver;

namespace {

// A x B x C grid, `dofs` unknowns per node (the last node may carry fewer, so that the size need not
// be a multiple of three): a grid Laplacian coupling every unknown of a node to its neighbours',
// with random weights, plus `shift` on the diagonal.
Eigen::MatrixXd gridMatrix(int a, int b, int c, int dofs, int drop, double shift) {
  const int nodes = a * b * c, n = nodes * dofs - drop;
  std::mt19937 random(7);
  std::uniform_real_distribution<double> weight(0.5, 2.0);
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(n, n);
  auto node = [&](int i, int j, int k) { return (k * b + j) * a + i; };
  auto couple = [&](int p, int q) {
    for (int s = 0; s < dofs; ++s)
      for (int t = 0; t < dofs; ++t) {
        const int u = p * dofs + s, v = q * dofs + t;
        if (u >= n || v >= n) continue;
        const double w = weight(random) / (s == t ? 1 : 4);
        A(u, u) += w;
        A(v, v) += w;
        A(u, v) -= w;
        A(v, u) -= w;
      }
  };
  for (int k = 0; k < c; ++k)
    for (int j = 0; j < b; ++j)
      for (int i = 0; i < a; ++i) {
        if (i + 1 < a) couple(node(i, j, k), node(i + 1, j, k));
        if (j + 1 < b) couple(node(i, j, k), node(i, j + 1, k));
        if (k + 1 < c) couple(node(i, j, k), node(i, j, k + 1));
      }
  A.diagonal().array() += shift;
  return A;
}

PetscMat petscMatrix(const Eigen::MatrixXd& A) {
  PetscMat out;
  const PetscInt n = A.rows();
  QV_PETSC(MatCreateSeqAIJ(PETSC_COMM_SELF, n, n, 400, nullptr, out.out()));
  for (PetscInt i = 0; i < n; ++i)
    for (PetscInt j = 0; j < n; ++j)
      if (A(i, j) != 0) QV_PETSC(MatSetValue(out, i, j, A(i, j), INSERT_VALUES));
  QV_PETSC(MatAssemblyBegin(out, MAT_FINAL_ASSEMBLY));
  QV_PETSC(MatAssemblyEnd(out, MAT_FINAL_ASSEMBLY));
  return out;
}

double relativeError(const Eigen::MatrixXd& A, const SequentialCholesky& factor) {
  const Eigen::MatrixXd B = Eigen::MatrixXd::Random(A.rows(), 5);
  Eigen::MatrixXd X = B;
  factor.solveInPlace(X.data(), X.cols());
  const Eigen::MatrixXd reference = A.ldlt().solve(B);
  return (X - reference).norm() / reference.norm();
}

} // namespace

TEST(SequentialCholesky, SolvesLikeADenseFactorInVertexTriplesAndNot) {
  for (int drop : {0, 1}) {  // 3 x 70 rows (the vertex graph), then 209 (each row a node)
    const Eigen::MatrixXd A = gridMatrix(7, 5, 2, 3, drop, 1e-3);
    const PetscMat matrix = petscMatrix(A);
    const SequentialCholesky factor(SequentialCholesky::upperTriangle(matrix));
    EXPECT_EQ(factor.rows(), A.rows());
    EXPECT_EQ(factor.orderingUsed(), 1);  // METIS's, given to MUMPS
    EXPECT_LT(relativeError(A, factor), 1e-12) << "rows " << A.rows();
  }
}

TEST(SequentialCholesky, MumpsOwnOrderingWhenAskedGivesTheSameSolution) {
  const Eigen::MatrixXd A = gridMatrix(6, 4, 3, 3, 0, 1e-3);
  const PetscMat matrix = petscMatrix(A);
  QV_PETSC(PetscOptionsSetValue(nullptr, "-factor_mat_mumps_icntl_7", "4"));  // PORD
  std::unique_ptr<SequentialCholesky> factor;
  EXPECT_NO_THROW(factor = std::make_unique<SequentialCholesky>(SequentialCholesky::upperTriangle(matrix)));
  QV_PETSC(PetscOptionsClearValue(nullptr, "-factor_mat_mumps_icntl_7"));
  ASSERT_TRUE(factor);
  EXPECT_EQ(factor->orderingUsed(), 4);
  EXPECT_LT(relativeError(A, *factor), 1e-12);
}

TEST(SequentialCholesky, RefusesAnIndefiniteMatrix) {
  const Eigen::MatrixXd A = gridMatrix(5, 4, 2, 3, 0, -2.0);  // the Laplacian's lowest eigenvalues shifted below 0
  ASSERT_LT(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(A).eigenvalues()[0], 0);
  const PetscMat matrix = petscMatrix(A);
  try {
    SequentialCholesky factor(SequentialCholesky::upperTriangle(matrix));
    FAIL() << "an indefinite matrix was factored";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("not positive definite"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("negative pivots"), std::string::npos) << e.what();
  }
}

// A factor kept refactorable takes new values on the same pattern (the order and analysis of the
// first): each solves like a dense factor of its own matrix; an indefinite one is refused, nothing
// solves until the next one factors again.
TEST(SequentialCholesky, RefactorsNewValuesOnTheSamePattern) {
  const Eigen::MatrixXd A = gridMatrix(5, 4, 3, 3, 0, 0.5);
  std::mt19937 random(3);
  std::uniform_real_distribution<double> noise(-0.2, 0.2);
  Eigen::MatrixXd B = A;
  for (Eigen::Index i = 0; i < B.rows(); ++i)
    for (Eigen::Index j = i; j < B.cols(); ++j)
      if (A(i, j) != 0) B(i, j) = B(j, i) = A(i, j) * (1 + noise(random));
  B.diagonal().array() += 1.0;  // kept positive definite
  Eigen::MatrixXd indefinite = B;
  indefinite.diagonal().array() -= 20.0;
  ASSERT_LT(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(indefinite).eigenvalues()[0], 0);
  const auto valuesOf = [&](const Eigen::MatrixXd& M) {  // in the order of A's upper triangle
    std::vector<double> values;
    const SequentialCholesky::UpperTriangle pattern = SequentialCholesky::upperTriangle(petscMatrix(A));
    for (size_t e = 0; e < pattern.rows.size(); ++e) values.push_back(M(pattern.rows[e], pattern.cols[e]));
    return values;
  };
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(A.rows(), -1.0, 2.0);
  const auto solve = [&](const SequentialCholesky& factor) {
    Eigen::VectorXd x = b;
    factor.solveInPlace(x.data(), 1);
    return x;
  };
  SequentialCholesky factor(SequentialCholesky::upperTriangle(petscMatrix(A)), 0, true);
  EXPECT_LT((solve(factor) - A.llt().solve(b)).norm(), 1e-12 * b.norm());
  factor.refactor(valuesOf(B));
  EXPECT_LT((solve(factor) - B.llt().solve(b)).norm(), 1e-12 * b.norm());
  EXPECT_THROW(factor.refactor(valuesOf(indefinite)), NotPositiveDefinite);
  EXPECT_THROW(solve(factor), std::logic_error);  // no factor to solve with until a refactor succeeds
  factor.refactor(valuesOf(A));
  EXPECT_LT((solve(factor) - A.llt().solve(b)).norm(), 1e-12 * b.norm());
  EXPECT_THROW(factor.refactor(std::vector<double>(3, 1.0)), std::logic_error);
  SequentialCholesky once(SequentialCholesky::upperTriangle(petscMatrix(A)));
  EXPECT_THROW(once.refactor(valuesOf(B)), std::logic_error);
}

// With the last variables left out: the Schur complement a dense elimination gives, and condense,
// a dense solve on the Schur variables and expand together solve the whole system. A small Schur
// block, and a large one with no entries of its own (as SplitCholesky gives it): MUMPS returns the
// two differently.
TEST(SequentialCholesky, SchurComplementAndTwoStepSolveMatchDenseAlgebra) {
  for (const Eigen::Index s : {21, 300}) {
    Eigen::MatrixXd A = gridMatrix(10, 8, 6, 3, 0, 1e-3);
    const Eigen::Index n = A.rows(), m = n - s;
    if (s > 100) A.bottomRightCorner(s, s).setZero();
    SequentialCholesky factor(SequentialCholesky::upperTriangle(petscMatrix(A)), s);
    const Eigen::MatrixXd S = factor.takeSchurComplement();
    const Eigen::LDLT<Eigen::MatrixXd> interior(A.topLeftCorner(m, m));
    const Eigen::MatrixXd reference = A.bottomRightCorner(s, s) - A.bottomLeftCorner(s, m) * interior.solve(A.topRightCorner(m, s));
    ASSERT_EQ(S.rows(), s);
    EXPECT_LT((S - reference).norm(), 1e-12 * reference.norm()) << s;
    EXPECT_EQ(factor.takeSchurComplement().size(), 0);  // taken

    const Eigen::MatrixXd B = Eigen::MatrixXd::Random(n, 4);
    Eigen::MatrixXd X = B, reduced(s, 4);
    factor.condense(X.data(), 4, reduced.data());
    const Eigen::MatrixXd expectedReduced = B.bottomRows(s) - A.bottomLeftCorner(s, m) * interior.solve(B.topRows(m));
    EXPECT_LT((reduced - expectedReduced).norm(), 1e-12 * expectedReduced.norm()) << s;
    const Eigen::MatrixXd schurSolution = reference.ldlt().solve(reduced);
    factor.expand(X.data(), 4, schurSolution.data());
    const Eigen::MatrixXd expected = A.ldlt().solve(B);
    EXPECT_LT((X - expected).norm(), 1e-10 * expected.norm()) << s;
  }
}
