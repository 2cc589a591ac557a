#include "apps/view/view_session.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

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

// The free beam (fixture test_model: 0.6 x 0.1 x 0.1 m, baked with no fixed vertex) dropped from
// 0.2 m onto a ground plane.
class FreeViewSessionTest : public ::testing::Test {
protected:
  RuntimeModel model{QUIVER_FREE_MODEL};
  static ViewSettings flying() {
    ViewSettings s;
    s.step.freeFlight = true;
    s.step.alpha = 5;
    s.gravity = true;
    return s;
  }
  static FlightSetup dropped(int pile = 1) {
    FlightSetup f;
    f.position = {0, 0, 0.2};
    f.colliders = {"plane:0,0,1,0"};
    f.pile = pile;
    return f;
  }
  static qv_rigid_state frame(const ViewSession& session, int body = 0) {
    qv_rigid_state s;
    qv_instance_get_rigid_state(session.flight()->body(body).get(), &s);
    return s;
  }
  static void run(ViewSession& session, double seconds) {
    for (int frame = 0; frame < std::lround(60 * seconds); ++frame) session.advance(1.0 / 60);
  }
};

TEST_F(FreeViewSessionTest, ItDropsLiftsOnTheSpringAndFliesWhereItIsThrown) {
  ViewSession session(model, flying(), dropped());
  run(session, 1.5);
  EXPECT_NEAR(frame(session).position[2], 0.05, 3e-3) << "landed on its underside";
  // Press straight down on the top face at its middle, then pull the target up in the vertical
  // plane y = 0.05 (the plane faces the viewer at -y).
  ASSERT_TRUE(session.press(Ray{{0.3, 0.05, 1}, {0, 0, -1}}, {0, -1, 0}));
  const auto cursor = [](double x, double z) { return Ray{{x, -1, z}, {0, 1, 0}}; };
  for (int k = 1; k <= 30; ++k) {
    session.drag(cursor(0.3, 0.1 + 0.3 * k / 30));
    session.advance(1.0 / 60);
  }
  run(session, 1);
  const qv_rigid_state held = frame(session);
  std::printf("held at z = %.3f m by a vertex targeted at 0.4 m\n", held.position[2]);
  EXPECT_GT(held.position[2], 0.25) << "lifted off the ground";
  // Swing the cursor 0.4 m along x in 1/6 s (2.4 m/s) and let go.
  for (int k = 1; k <= 10; ++k) {
    session.drag(cursor(0.3 + 0.04 * k, 0.4));
    session.advance(1.0 / 60);
  }
  session.release();
  const qv_rigid_state thrown = frame(session);
  std::printf("let go at %.2f m/s along x\n", thrown.linear_velocity[0]);
  EXPECT_GT(thrown.linear_velocity[0], 0.5);
  run(session, 2);
  const qv_rigid_state landed = frame(session);
  std::printf("landed at x = %.3f m (thrown from %.3f m)\n", landed.position[0], thrown.position[0]);
  EXPECT_GT(landed.position[0], thrown.position[0] + 0.1);
  EXPECT_NEAR(landed.position[2], 0.05, 0.01);
  EXPECT_EQ(session.resets(), 0);
  // Drop again: back where it started, falling.
  session.reset();
  EXPECT_NEAR(frame(session).position[2], 0.25, 1e-12);
  EXPECT_THROW(session.showMode(ModeKind::LinearMode, 0, 0.01), std::logic_error);
}

TEST_F(FreeViewSessionTest, APileIsDrawnAsAllItsBodiesAndComesToRest) {
  FlightSetup awake = dropped(8);
  awake.sleepSpeed = 0;  // it must come to rest by itself, not be put to sleep
  ViewSession session(model, flying(), awake);
  ASSERT_EQ(session.bodyCount(), 8);
  const size_t n = static_cast<size_t>(model.info().vertex_count);
  std::vector<float> x, normals;
  session.positions(x);
  session.normals(x, normals);
  EXPECT_EQ(x.size(), 3 * 8 * n);
  EXPECT_EQ(normals.size(), x.size());
  EXPECT_EQ(session.triangles().size(), 8 * model.triangles().size());
  for (unsigned index : session.triangles()) ASSERT_LT(index, 8 * n);
  run(session, 3);
  for (int k = 0; k < 8; ++k) {
    const qv_rigid_state s = frame(session, k);
    EXPECT_LT(std::hypot(s.linear_velocity[0], s.linear_velocity[1], s.linear_velocity[2]), 1e-3) << "body " << k;
    EXPECT_GT(s.position[2], 0.04) << "body " << k;
  }
}

} // namespace
} // namespace quiver::app
