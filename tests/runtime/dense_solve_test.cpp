#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <random>

#include "runtime/src/dense_solve.h"

using namespace quiver::rt;

TEST(DenseSolve, CholeskyAndPivotingLuAgainstEigen) {
  std::mt19937 rng(2);
  std::normal_distribution<double> n(0, 1);
  for (int size : {1, 5, 30}) {
    Eigen::MatrixXd B(size, size);
    for (auto& x : B.reshaped()) x = n(rng);
    const Eigen::MatrixXd spd = B * B.transpose() + Eigen::MatrixXd::Identity(size, size);
    Eigen::MatrixXd indefinite = B + B.transpose();
    indefinite(0, 0) = -std::abs(indefinite(0, 0)) - 1;  // at least one negative direction
    Eigen::VectorXd b(size);
    for (auto& x : b) x = n(rng);
    using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
    RowMajor A = spd;
    A.triangularView<Eigen::StrictlyLower>().setConstant(std::nan(""));  // Cholesky reads the upper triangle only
    Eigen::VectorXd x = b;
    ASSERT_TRUE(choleskySolve(A.data(), x.data(), size));
    EXPECT_LT((x - spd.llt().solve(b)).norm(), 1e-10 * x.norm());
    A = indefinite;
    x = b;
    EXPECT_FALSE(choleskySolve(A.data(), x.data(), size));
    A = indefinite;
    x = b;
    std::vector<int> pivot(size);
    ASSERT_TRUE(luSolve(A.data(), x.data(), pivot.data(), size));
    EXPECT_LT((indefinite * x - b).norm(), 1e-9 * b.norm());
  }
  Eigen::Matrix3d singular = Eigen::Matrix3d::Ones();
  Eigen::Vector3d rhs(1, 2, 3);
  int pivot[3];
  EXPECT_FALSE(luSolve(singular.data(), rhs.data(), pivot, 3));
}
