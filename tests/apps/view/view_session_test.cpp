#include "apps/view/view_session.h"

#include <gtest/gtest.h>

#include <cmath>

#include <Eigen/Dense>

namespace quiver::app {
namespace {

// The suite's baked beam (fixture runtime_model), fixed at x = min.
class ViewSessionTest : public ::testing::Test {
protected:
  RuntimeModel model{QUIVER_RUNTIME_MODEL};
  double h() const { return model.info().time_step; }
};

TEST_F(ViewSessionTest, StepsAtTheModelsRateWhateverTheFrameRate) {
  ViewSession session(model, ViewSettings{});
  EXPECT_EQ(session.advance(0.4 * h()), 0);
  EXPECT_EQ(session.advance(0.4 * h()), 0);
  EXPECT_EQ(session.advance(0.4 * h()), 1) << "the fractions add up to one step";
  int steps = 0;
  for (int frame = 0; frame < 144; ++frame) steps += session.advance(1.0 / 144);  // a 144 Hz display for 1 s
  EXPECT_NEAR(steps, std::lround(1 / h()), 1);
  EXPECT_FALSE(session.behindRealTime());
}

TEST_F(ViewSessionTest, DropsTimeItCannotCatchUpInsteadOfSpiralling) {
  ViewSession session(model, ViewSettings{});
  EXPECT_EQ(session.advance(1000 * h()), ViewSession::kMaxStepsPerFrame);
  EXPECT_TRUE(session.behindRealTime());
  EXPECT_EQ(session.advance(h()), 1) << "the backlog was dropped";
  EXPECT_FALSE(session.behindRealTime());
}

TEST_F(ViewSessionTest, TheSpringPullsTheGrabbedVertexTowardItsTarget) {
  ViewSettings damped;
  damped.step.alpha = 20;  // about critical for the first mode: the tip settles within the test's 2 s
  ViewSession session(model, damped);
  std::vector<float> x;
  session.positions(x);
  int tip = 0;  // the free end's corner: largest x
  for (int v = 0; v < model.info().vertex_count; ++v)
    if (x[3 * v] > x[3 * tip]) tip = v;
  const Eigen::Vector3d rest(x[3 * tip], x[3 * tip + 1], x[3 * tip + 2]), target = rest - Eigen::Vector3d(0, 0, 0.05);
  session.grab(tip, target);
  for (int frame = 0; frame < 120; ++frame) session.advance(1.0 / 60);
  session.positions(x);
  const Eigen::Vector3d pulled(x[3 * tip], x[3 * tip + 1], x[3 * tip + 2]);
  EXPECT_LT(pulled.z(), rest.z() - 0.005) << "moved down a good part of the 5 cm";
  EXPECT_LT((pulled - target).norm(), 0.5 * (rest - target).norm());
  session.release();
  EXPECT_FALSE(session.grabbing());
  EXPECT_EQ(session.resets(), 0);
}

TEST_F(ViewSessionTest, APressHeldStillPullsNothingAndADragPullsAlongTheRay) {
  ViewSession session(model, ViewSettings{});
  const qv_model_info& info = model.info();
  // Straight down onto the top face near the free end (the beam is fixed at x = min).
  const Eigen::Vector3d above(0.9 * info.bbox_max[0] + 0.1 * info.bbox_min[0], 0.3 * info.bbox_max[1], info.bbox_max[2] + 1);
  const Ray down{above, {0, 0, -1}};
  ASSERT_TRUE(session.press(down, {0, 0, 1}));
  EXPECT_FALSE(session.press(Ray{above, {0, 0, 1}}, {0, 0, 1})) << "up, away from the beam";
  for (int frame = 0; frame < 60; ++frame) {
    session.drag(down);
    session.advance(1.0 / 60);
  }
  EXPECT_LT(session.energies().kinetic + session.energies().elastic, 1e-12) << "the spring starts at the grabbed vertex";
  // The cursor 2 cm toward -y: the target moves 2 cm in the plane z = top, and the vertex follows.
  std::vector<float> before, after;
  session.positions(before);
  const Ray aside{above - Eigen::Vector3d(0, 0.02, 0), {0, 0, -1}};
  for (int frame = 0; frame < 30; ++frame) {
    session.drag(aside);
    session.advance(1.0 / 60);
  }
  const int v = session.grabbedVertex();
  EXPECT_NEAR((session.grabTarget() - Eigen::Vector3d(before[3 * v], before[3 * v + 1] - 0.02, before[3 * v + 2])).norm(), 0, 1e-12);
  session.positions(after);
  EXPECT_LT(after[3 * v + 1], before[3 * v + 1] - 0.002);
}

TEST_F(ViewSessionTest, SameStepsAsTheRuntimeAlone) {
  ViewSettings settings;
  settings.gravity = true;
  ViewSession session(model, settings);
  const double g[3] = {0, 0, -9.81};
  RuntimeInstance reference(model, session.config());
  qv_instance_set_gravity(reference.get(), g);
  for (int i = 0; i < 30; ++i) qv_instance_step(reference.get());
  EXPECT_EQ(session.advance(30.5 * h()), 30);
  std::vector<float> a, b(3 * static_cast<size_t>(model.info().vertex_count));
  session.positions(a);
  qv_instance_positions(reference.get(), b.data());
  EXPECT_EQ(a, b) << "bit-identical: the runtime is deterministic";
}

TEST_F(ViewSessionTest, NewSettingsContinueFromTheSameState) {
  ViewSettings settings;
  ViewSession session(model, settings);
  settings.gravity = true;
  session.configure(settings);
  session.advance(20 * h());
  std::vector<float> before, after;
  session.positions(before);
  settings.step.integrator = QV_INTEGRATOR_BACKWARD_EULER;
  settings.step.timeStep = h() / 2;
  session.configure(settings);
  EXPECT_EQ(session.config().integrator, QV_INTEGRATOR_BACKWARD_EULER);
  EXPECT_EQ(session.config().time_step, h() / 2);
  session.positions(after);
  EXPECT_EQ(before, after);
  session.advance(h() / 2);
  session.positions(after);

  // The same by hand: 20 steps under gravity, then a new instance from that state, still under gravity.
  const double g[3] = {0, 0, -9.81};
  const int r = model.info().r;
  std::vector<double> q(r), v(r);
  ViewSettings first;
  RuntimeInstance a(model, ViewSession(model, first).config());
  qv_instance_set_gravity(a.get(), g);
  for (int i = 0; i < 20; ++i) qv_instance_step(a.get());
  qv_instance_get_state(a.get(), q.data(), v.data(), nullptr);
  RuntimeInstance b(model, session.config());
  qv_instance_set_gravity(b.get(), g);
  qv_instance_set_state(b.get(), q.data(), v.data(), nullptr);
  qv_instance_step(b.get());
  EXPECT_EQ(after, b.positions());

  const int iterations = session.config().newton_iterations;
  settings.step.newton = -1;
  EXPECT_THROW(session.configure(settings), std::runtime_error);
  EXPECT_EQ(session.config().newton_iterations, iterations) << "refused settings leave the old ones";
}

TEST_F(ViewSessionTest, ModesAreEigenvectorsOfTheReducedStiffnessShownAtTheirAmplitude) {
  ViewSession session(model, ViewSettings{});
  const int r = model.info().r;
  std::vector<double> stiffness(static_cast<size_t>(r) * r), q(r, 0.0);
  std::vector<double> scratch(qv_model_scratch_size(model.get()) / sizeof(double) + 1);
  qv_model_evaluate(model.get(), q.data(), nullptr, nullptr, stiffness.data(), scratch.data());
  const Eigen::Map<Eigen::MatrixXd> K(stiffness.data(), r, r);
  const ReducedModes& modes = session.modes();
  for (int i = 0; i < r; ++i) {
    const Eigen::VectorXd x = modes.vectors.col(i);
    EXPECT_LT((K * x - modes.eigenvalues[i] * x).norm(), 1e-9 * K.norm());
    if (i > 0) {
      EXPECT_GE(modes.eigenvalues[i], modes.eigenvalues[i - 1]);
    }
  }
  const double amplitude = 0.03;
  session.showMode(ModeKind::LinearMode, 0, amplitude);
  const qv_model_info& info = model.info();
  const double* rest = qv_model_rest_positions(model.get());
  const auto largest = [&] {
    std::vector<float> x;
    session.positions(x);
    double most = 0;
    for (size_t k = 0; k < x.size(); k += 3)
      most = std::max(most, std::hypot(x[k] - rest[k], x[k + 1] - rest[k + 1], x[k + 2] - rest[k + 2]));
    return most;
  };
  EXPECT_LT(largest(), 1e-6) << "starts at rest (float positions)";
  EXPECT_EQ(session.advance(ViewSession::kModePeriod / 4), 0) << "no simulation while a mode is shown";
  EXPECT_NEAR(largest(), amplitude, 1e-6) << "a quarter period: full amplitude";
  session.showMode(ModeKind::BasisVector, info.r - 1, amplitude);
  session.advance(ViewSession::kModePeriod / 4);
  EXPECT_NEAR(largest(), amplitude, 1e-6);
  EXPECT_THROW(session.showMode(ModeKind::BasisVector, info.r, amplitude), std::out_of_range);
  session.showMode(ModeKind::None, 0, 0);
  EXPECT_EQ(session.advance(h()), 1);
}

} // namespace
} // namespace quiver::app
