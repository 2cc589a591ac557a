#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cstdio>

#include "quiver/modal_warping.h"

using quiver::warping::warpDisplacement;

// The warped displacement of a point under the rotation w, from the linear one w x X: the rotated
// point R(w) X - X exactly, R the finite rotation by |w| about w; and no change for tiny rotations.
TEST(ModalWarping, RecoversFiniteRotationsAndIsLinearForSmallOnes) {
  const Eigen::Vector3d X(0.8, -0.3, 0.5), axis = Eigen::Vector3d(1, 2, -0.5).normalized();
  for (double angle : {1e-6, 0.3, 1.2, 2.5}) {
    const Eigen::Vector3d w = angle * axis, linear = w.cross(X);
    const Eigen::Vector3d exact = Eigen::AngleAxisd(angle, axis) * X - X;
    Eigen::Vector3d warped;
    warpDisplacement(w.data(), linear.data(), warped.data());
    EXPECT_LT((warped - exact).norm(), 1e-12 * std::max(1.0, exact.norm())) << "angle " << angle;
    EXPECT_NEAR((X + warped).norm(), X.norm(), 1e-12);  // a rotation keeps lengths; linear w x X does not
  }
  const Eigen::Vector3d small(1e-7, 0, 0), linear(0.1, 0.2, 0.3);
  Eigen::Vector3d warped;
  warpDisplacement(small.data(), linear.data(), warped.data());
  EXPECT_LT((warped - linear).norm(), 1e-7 * linear.norm());
}

#include "tests/runtime/runtime_fixture.h"

namespace {

// Length of the bar's centre line (the vertices on y = z = 0.05 of the 0.6 x 0.1 x 0.1 bar).
double centreLineLength(const quiver::test::TestModel& m, const std::vector<float>& p) {
  std::vector<std::pair<double, int>> line;
  for (int v = 0; v < m.info.vertex_count; ++v)
    if (std::abs(m.mesh.vertices[v].y() - 0.05) < 1e-9 && std::abs(m.mesh.vertices[v].z() - 0.05) < 1e-9)
      line.emplace_back(m.mesh.vertices[v].x(), v);
  std::sort(line.begin(), line.end());
  double length = 0;
  for (size_t k = 1; k < line.size(); ++k) {
    const int a = line[k - 1].second, b = line[k].second;
    length += Eigen::Vector3d(p[3 * b] - p[3 * a], p[3 * b + 1] - p[3 * a + 1], p[3 * b + 2] - p[3 * a + 2]).norm();
  }
  return length;
}

std::vector<float> positions(const qv_model* model, const std::vector<double>& q, bool warping) {
  qv_instance_config config;
  qv_instance_config_init(&config, model);
  config.elasticity = warping ? QV_ELASTICITY_MODAL_WARPING : QV_ELASTICITY_STVK;
  qv_instance* s = nullptr;
  EXPECT_EQ(qv_instance_create(model, &config, nullptr, &s), QV_OK);
  qv_instance_set_state(s, q.data(), nullptr, nullptr);
  qv_model_info info;
  qv_model_get_info(model, &info);
  std::vector<float> p(3 * static_cast<size_t>(info.vertex_count));
  qv_instance_positions(s, p.data());
  qv_instance_destroy(s);
  return p;
}

} // namespace

// Bending along the first basis vector: at a tiny amplitude warping changes nothing; at a large
// one linear modal displacements stretch the bar (its tip moves straight sideways) while the
// warped ones keep its length (the rotation carries the tip along an arc).
TEST(ModalWarping, SmallDeformationsUnchangedLargeBendsKeepTheLength) {
  quiver::test::TestModel m;
  ASSERT_NE(m.model, nullptr);
  ASSERT_EQ(m.info.has_modal_rotations, 1);
  const double L = 0.6, tipPerUnit = m.U.col(0).cwiseAbs().maxCoeff();
  std::vector<double> q(m.info.r, 0.0);
  q[0] = 1e-5 * L / tipPerUnit;
  const std::vector<float> rest = positions(m.model, std::vector<double>(m.info.r, 0.0), false);
  std::vector<float> lin = positions(m.model, q, false), warp = positions(m.model, q, true);
  double diff = 0, moved = 0;
  for (size_t i = 0; i < lin.size(); ++i) {
    diff = std::max(diff, double(std::abs(lin[i] - warp[i])));
    moved = std::max(moved, double(std::abs(lin[i] - rest[i])));
  }
  EXPECT_LT(diff, 1e-3 * moved);
  q[0] = 0.4 * L / tipPerUnit;  // the tip swings by 40% of the length
  lin = positions(m.model, q, false);
  warp = positions(m.model, q, true);
  const double linear = centreLineLength(m, lin) / L - 1, warped = centreLineLength(m, warp) / L - 1;
  EXPECT_GT(linear, 0.03);
  EXPECT_LT(std::abs(warped), 0.3 * linear);
  RecordProperty("stretch_linear", std::to_string(linear));
  RecordProperty("stretch_warped", std::to_string(warped));
  std::printf("centre line: linear %+.2f%%, warped %+.2f%%\n", 100 * linear, 100 * warped);
}

TEST(ModalWarping, StepsWithForcesRotatedIntoTheLocalFrames) {
  quiver::test::TestModel m;
  ASSERT_NE(m.model, nullptr);
  qv_instance_config config;
  qv_instance_config_init(&config, m.model);
  config.elasticity = QV_ELASTICITY_MODAL_WARPING;
  qv_instance* s = nullptr;
  ASSERT_EQ(qv_instance_create(m.model, &config, nullptr, &s), QV_OK);
  for (int step = 0; step < 50; ++step) {
    const double push[3] = {0, 0, -5};
    qv_instance_add_vertex_force(s, m.tipVertex(), push);
    ASSERT_EQ(qv_instance_step(s), QV_STEP_OK);
  }
  qv_instance_destroy(s);
}
