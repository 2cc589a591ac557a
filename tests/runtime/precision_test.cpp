// float32 coefficients against float64 (exact) on the suite's model: the documented error bound.
#include <gtest/gtest.h>

#include <random>

#include "tests/runtime/runtime_fixture.h"

TEST(Precision, Float32CoefficientsStayWithinTheDocumentedError) {
  quiver::test::TestModel m;
  ASSERT_NE(m.model, nullptr);
  qv_model_config single;
  qv_model_config_init(&single);
  single.coefficient_precision = 32;
  qv_model* model32 = nullptr;
  ASSERT_EQ(qv_model_load_file(QUIVER_RUNTIME_MODEL, &single, nullptr, &model32, nullptr, 0), QV_OK);
  const int r = m.info.r;
  std::vector<double> scratch(std::max(qv_model_scratch_size(m.model), qv_model_scratch_size(model32)) / 8 + 1);
  std::mt19937 rng(4);
  std::normal_distribution<double> n(0, 1);
  double worstForce = 0, worstStiffness = 0;
  for (int trial = 0; trial < 20; ++trial) {
    Eigen::VectorXd q(r);
    for (auto& x : q) x = n(rng);
    q *= 0.3 / (m.U * q).cwiseAbs().maxCoeff();  // up to half the bar's length: the quartic part dominates
    Eigen::VectorXd f64(r), f32(r);
    Eigen::MatrixXd K64(r, r), K32(r, r);
    qv_model_evaluate(m.model, q.data(), nullptr, f64.data(), K64.data(), scratch.data());
    qv_model_evaluate(model32, q.data(), nullptr, f32.data(), K32.data(), scratch.data());
    worstForce = std::max(worstForce, (f32 - f64).norm() / f64.norm());
    worstStiffness = std::max(worstStiffness, (K32 - K64).norm() / K64.norm());
  }
  qv_model_destroy(model32);
  EXPECT_LT(worstForce, 1e-6);
  EXPECT_LT(worstStiffness, 1e-6);
  EXPECT_GT(worstForce, 0.0);  // it is really the float32 path
  RecordProperty("float32_force_error", std::to_string(worstForce));
  RecordProperty("float32_stiffness_error", std::to_string(worstStiffness));
  std::printf("float32 coefficients: force error %.2e, stiffness error %.2e (relative, worst of 20)\n", worstForce,
              worstStiffness);
}
