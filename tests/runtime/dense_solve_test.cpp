#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "runtime/src/cholesky_lanes.h"
#include "runtime/src/dense_solve.h"

using namespace quiver::rt;

TEST(DenseSolve, CholeskyAgainstEigen) {
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
  }
}

TEST(DenseSolve, CholeskyLanesFactoriseEachLaneAsAloneAndKeepABadLaneToItself) {
  constexpr int L = kCholeskyLanes;
  std::mt19937 rng(7);
  std::normal_distribution<double> n(0, 1);
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  for (int size : {1, 7, 30}) {
    std::vector<Eigen::MatrixXd> spd(L);
    for (int l = 0; l < L; ++l) {
      Eigen::MatrixXd B(size, size);
      for (auto& x : B.reshaped()) x = n(rng);
      spd[l] = std::pow(10.0, l - 4) * (B * B.transpose() + 0.1 * Eigen::MatrixXd::Identity(size, size));
    }
    Eigen::MatrixXd indefinite = spd[5];
    indefinite(size - 1, size - 1) = -1;  // fails at the last pivot: every row before it is worked on
    const size_t packed = packedUpperIndex(size, size, size);
    auto interleave = [&](bool bad) {
      std::vector<double> A(packed * L);
      for (int l = 0; l < L; ++l)
        for (int i = 0; i < size; ++i)
          for (int j = i; j < size; ++j) A[packedUpperIndex(size, i, j) * L + l] = (bad && l == 5 ? indefinite : spd[l])(i, j);
      return A;
    };
    std::vector<double> good = interleave(false), bad = interleave(true);
    bool okGood[L], okBad[L];
    choleskyFactorLanes(good.data(), size, okGood);
    choleskyFactorLanes(bad.data(), size, okBad);
    for (int l = 0; l < L; ++l) {
      EXPECT_TRUE(okGood[l]) << size << " lane " << l;
      EXPECT_EQ(okBad[l], l != 5) << size << " lane " << l;
      RowMajor U = RowMajor::Zero(size, size), alone = spd[l];
      for (int i = 0; i < size; ++i)
        for (int j = i; j < size; ++j) {
          U(i, j) = good[packedUpperIndex(size, i, j) * L + l];
          if (l != 5) {
            EXPECT_EQ(bad[packedUpperIndex(size, i, j) * L + l], U(i, j)) << "the bad lane leaked into lane " << l;
          }
        }
      // Against the product, and against the one-matrix factorisation (the same operations; compiled
      // for other instruction sets, so to rounding).
      EXPECT_LT((U.transpose() * U - spd[l]).norm(), 1e-13 * spd[l].norm()) << size << " lane " << l;
      ASSERT_TRUE(choleskyFactor(alone.data(), size));
      EXPECT_LT((alone.triangularView<Eigen::Upper>().toDenseMatrix() - U).norm(), 1e-13 * U.norm()) << size << " lane " << l;
    }
  }
}

// The group's systems solved four lanes at a time (LanesFactor) give each lane the bits its own
// solve in its lane gives (LaneFactor: the same operations), and solve the system (Eigen).
TEST(DenseSolve, LanesSolvedTogetherAsEachAlone) {
  constexpr int L = kCholeskyLanes, W = LanesFactor::kWidth;
  std::mt19937 rng(4);
  std::normal_distribution<double> n(0, 1);
  for (int size : {1, 6, 30}) {
    std::vector<Eigen::MatrixXd> spd(L);
    std::vector<double> A(packedUpperIndex(size, size, size) * L);
    for (int l = 0; l < L; ++l) {
      Eigen::MatrixXd B(size, size);
      for (auto& x : B.reshaped()) x = n(rng);
      spd[l] = B * B.transpose() + 0.1 * Eigen::MatrixXd::Identity(size, size);
      for (int i = 0; i < size; ++i)
        for (int j = i; j < size; ++j) A[packedUpperIndex(size, i, j) * L + l] = spd[l](i, j);
    }
    bool ok[L];
    choleskyFactorLanes(A.data(), size, ok);
    std::vector<Eigen::VectorXd> rhs(L, Eigen::VectorXd(size));
    for (auto& b : rhs)
      for (auto& x : b) x = n(rng);
    for (int half = 0; half < L / W; ++half) {
      std::vector<LanesFactor::Value> together(size);
      for (int k = 0; k < size; ++k)
        for (int w = 0; w < W; ++w) together[k][w] = rhs[W * half + w](k);
      choleskySubstitute(LanesFactor{A.data(), size, half}, together.data(), size);
      for (int w = 0; w < W; ++w) {
        const int l = W * half + w;
        ASSERT_TRUE(ok[l]);
        Eigen::VectorXd alone = rhs[l];
        choleskySubstitute(LaneFactor{A.data(), size, l}, alone.data(), size);
        for (int k = 0; k < size; ++k) EXPECT_EQ(together[k][w], alone(k)) << size << " lane " << l << " entry " << k;
        EXPECT_LT((alone - spd[l].llt().solve(rhs[l])).norm(), 1e-10 * alone.norm()) << size << " lane " << l;
      }
    }
  }
}

TEST(DenseSolve, SymmetricEigenAgainstEigen) {
  std::mt19937 rng(3);
  std::normal_distribution<double> n(0, 1);
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  for (int size : {1, 2, 7, 40}) {
    Eigen::MatrixXd B(size, size);
    for (auto& x : B.reshaped()) x = n(rng);
    Eigen::MatrixXd symmetric = B + B.transpose();
    if (size > 2) {  // a repeated eigenvalue, as a square bar's two bending modes have
      const Eigen::MatrixXd Q = Eigen::HouseholderQR<Eigen::MatrixXd>(B).householderQ();
      Eigen::VectorXd lambda = Eigen::VectorXd::LinSpaced(size, 1, size);
      lambda(1) = lambda(0);
      symmetric = Q * lambda.asDiagonal() * Q.transpose();
    }
    RowMajor A = symmetric, V(size, size);
    symmetricEigen(A.data(), V.data(), size);
    const Eigen::VectorXd lambda = A.diagonal();
    EXPECT_LT((V * lambda.asDiagonal() * V.transpose() - symmetric).norm(), 1e-12 * symmetric.norm());
    EXPECT_LT((V.transpose() * V - Eigen::MatrixXd::Identity(size, size)).norm(), 1e-12 * size);
    Eigen::VectorXd sorted = lambda;
    std::sort(sorted.begin(), sorted.end());
    EXPECT_LT((sorted - Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(symmetric).eigenvalues()).norm(), 1e-12 * symmetric.norm());
  }
}
