// Time stepping against references the runtime did not compute: the same Newmark scheme driven by
// the full-space FEM projection, energy conservation, a static equilibrium found by a separate
// Newton solve, the stable step of central differences, and the real-time contract.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>
#include <vector>

#include "runtime/src/instance.h"
#include "tests/runtime/runtime_fixture.h"

using namespace quiver;

namespace {

using test::Instance;

Eigen::VectorXd state(const qv_instance* s, int r) {
  Eigen::VectorXd q(r);
  qv_instance_get_state(s, q.data(), nullptr, nullptr);
  return q;
}

} // namespace

// The reference integrates q'' + C q' + R(q) = f with implicit Newmark (beta 1/4, gamma 1/2) and R
// linearised at the step's start (one Newton iteration from there: Barbic & James, Vega's implicit
// Newmark, QV_SOLVER_NEWTON), R and K from U^T R(Uq) and U^T K(Uq) U, C = alpha I + beta K(q).
TEST(Step, NewmarkTrajectoryEqualsTheExactProjectionsOver1000Steps) {
  test::TestModel m;
  ASSERT_NE(m.model, nullptr);
  const int r = m.info.r, tip = m.tipVertex();
  qv_instance_config config;
  qv_instance_config_init(&config, m.model);
  config.solver = QV_SOLVER_NEWTON;
  config.newton_iterations = 1;
  config.time_step = 1e-2;
  Instance inst(m.model, config);
  const double h = config.time_step, alpha = config.rayleigh_alpha, beta = config.rayleigh_beta;
  const double pull[3] = {0, 0, -5.0};  // N at the tip: a deflection of about 7% of the bar's length
  const Eigen::VectorXd tipForce = m.U.middleRows(3 * tip, 3).transpose() * Eigen::Map<const Eigen::Vector3d>(pull);
  Eigen::VectorXd q = Eigen::VectorXd::Zero(r), v = q, a = q, f, R;
  Eigen::MatrixXd K;
  double worst = 0, largest = 0;
  for (int step = 0; step < 1000; ++step) {
    f = step < 300 ? tipForce : Eigen::VectorXd::Zero(r);
    if (step < 300) {
      ASSERT_EQ(qv_instance_add_vertex_force(inst.s, tip, pull), QV_OK);
    }
    ASSERT_NE(qv_instance_step(inst.s), QV_STEP_RESET) << "step " << step;
    // a' + C (v + h/2 (a + a')) + R(q) + K(q) (h v + h^2/4 (a + a')) = f, solved for a'.
    m.exact(q, R, K);
    const Eigen::MatrixXd C = alpha * Eigen::MatrixXd::Identity(r, r) + beta * K;
    const Eigen::MatrixXd A = Eigen::MatrixXd::Identity(r, r) + 0.5 * h * C + 0.25 * h * h * K;
    const Eigen::VectorXd next = A.partialPivLu().solve(f - R - C * (v + 0.5 * h * a) - K * (h * v + 0.25 * h * h * a));
    q += h * v + h * h * 0.25 * (a + next);
    v += h * 0.5 * (a + next);
    a = next;
    worst = std::max(worst, (state(inst.s, r) - q).norm());
    largest = std::max(largest, q.norm());
  }
  EXPECT_LT(worst, 1e-8 * largest);
  const Eigen::Vector3d tipMove = m.U.middleRows(3 * tip, 3) * q;
  RecordProperty("largest_tip_displacement", std::to_string(tipMove.norm()));
}

// The trapezoidal rule conserves energy exactly for linear systems; with StVK's nonlinearity at a
// 10% tip deflection it exchanges some with the discretisation, at second order: the dip must
// shrink about fourfold with each halving once the step resolves the motion, and (the default
// solver's energy budget) the energy never grows
// (measured 1.7%, 0.60%, 0.16% at 1, 0.5, 0.25 ms; 4.1%, 0.84%, 0.21% on the bake's own basis for
// this beam). (set_state gives the consistent initial acceleration: with a = 0 the first step
// injects ~5%.)
TEST(Step, UndampedNewmarkEnergyDipsAtSecondOrderAndNeverGrows) {
  test::TestModel m;
  ASSERT_NE(m.model, nullptr);
  const int r = m.info.r;
  // Start from a large static-looking deflection along the first basis vector, at rest.
  Eigen::VectorXd q0 = Eigen::VectorXd::Zero(r);
  q0[0] = 0.1 * (m.mesh.vertices[m.tipVertex()].x()) / m.U.col(0).cwiseAbs().maxCoeff();
  const double initial = m.elasticEnergy(q0);
  double dips[3];
  for (int halvings = 0; halvings < 3; ++halvings) {
    qv_instance_config config;
    qv_instance_config_init(&config, m.model);
    config.rayleigh_alpha = config.rayleigh_beta = 0;
    config.newton_iterations = 3;
    config.time_step = 1e-3 / (1 << halvings);
    Instance inst(m.model, config);
    qv_instance_set_state(inst.s, q0.data(), nullptr, nullptr);
    double lo = initial, hi = initial;
    for (int step = 0; step < 10000 << halvings; ++step) {  // 10 s each
      ASSERT_EQ(qv_instance_step(inst.s), QV_STEP_OK);
      double kinetic = 0, elastic = 0;
      qv_instance_energies(inst.s, &kinetic, &elastic);
      lo = std::min(lo, kinetic + elastic);
      hi = std::max(hi, kinetic + elastic);
    }
    std::printf("time step %g s: the energy within %.5f .. %.5f of its start\n", config.time_step, lo / initial,
                hi / initial);
    EXPECT_LT(hi, (1 + 1e-9) * initial) << config.time_step;
    EXPECT_GT(lo, 0.95 * initial) << config.time_step;
    dips[halvings] = 1 - lo / initial;
  }
  EXPECT_LT(dips[2], dips[1] / 3);
}

TEST(Step, DampedMotionComesToRestAtTheStaticEquilibrium) {
  test::TestModel m;
  ASSERT_NE(m.model, nullptr);
  const int r = m.info.r;
  qv_instance_config config;
  qv_instance_config_init(&config, m.model);
  config.rayleigh_alpha = 20;  // heavily damped: settles in a few hundred steps
  config.time_step = 1e-2;
  Instance inst(m.model, config);
  const double g[3] = {0, 0, -9.81};  // a soft bar (E = 1 MPa): it sags by a good fraction of its length
  qv_instance_set_gravity(inst.s, g);
  for (int step = 0; step < 3000; ++step) ASSERT_NE(qv_instance_step(inst.s), QV_STEP_RESET) << "step " << step;
  // Separate Newton solve of U^T R(Uq) = U^T M g with the full-space FEM.
  Eigen::VectorXd fg = Eigen::VectorXd::Zero(r), q = Eigen::VectorXd::Zero(r), R;
  const double* G = qv_model_gravity(m.model);
  for (int j = 0; j < r; ++j) fg[j] = G[2 * r + j] * g[2];
  Eigen::MatrixXd K;
  for (int it = 0; it < 30; ++it) {
    m.exact(q, R, K);
    q -= K.ldlt().solve(R - fg);
  }
  m.exact(q, R, K);
  ASSERT_LT((R - fg).norm(), 1e-10 * fg.norm());
  EXPECT_LT((state(inst.s, r) - q).norm(), 1e-6 * q.norm());
}

// Undamped, and under Rayleigh damping strong enough to lower the limit well below 2 / omega_max
// (whose explicit stiffness-proportional part once made runs blow up at a seventh of the step
// reported), mass-proportional damping, and both.
TEST(Step, CentralDifferencesAreStableJustBelowTheReportedStepAndNotAbove) {
  test::TestModel m;
  ASSERT_NE(m.model, nullptr);
  qv_instance_config config;
  qv_instance_config_init(&config, m.model);
  config.integrator = QV_INTEGRATOR_CENTRAL_DIFFERENCES;
  config.rayleigh_alpha = config.rayleigh_beta = 0;
  const double undamped = qv_instance_stable_time_step(Instance(m.model, config).s);
  ASSERT_GT(undamped, 0);
  const double omega = 2 / undamped;
  for (const auto& [alpha, beta] : {std::pair{0.0, 0.0}, {0.0, 5 / omega}, {5 * omega, 0.0}, {omega, 1 / omega}}) {
    config.rayleigh_alpha = alpha;
    config.rayleigh_beta = beta;
    const double critical = qv_instance_stable_time_step(Instance(m.model, config).s);
    ASSERT_GT(critical, 0);
    if (alpha > 0 || beta > 0) {
      EXPECT_LT(critical, 0.5 * undamped) << "the damping should lower the limit";
    }
    for (const double factor : {0.97, 1.03}) {
      config.time_step = factor * critical;
      Instance inst(m.model, config);
      std::vector<double> q0(m.info.r, 1e-6);  // tiny: the linear regime the bound is about
      qv_instance_set_state(inst.s, q0.data(), nullptr, nullptr);
      double peak = 0;
      bool reset = false;
      for (int step = 0; step < 4000 && !reset; ++step) {
        reset = qv_instance_step(inst.s) == QV_STEP_RESET;
        peak = std::max(peak, state(inst.s, m.info.r).cwiseAbs().maxCoeff());
      }
      if (factor < 1)
        EXPECT_TRUE(!reset && peak < 1e-5) << "unstable below the reported step, alpha " << alpha << " beta " << beta;
      else
        EXPECT_TRUE(reset || peak > 1e-3) << "stable above the reported step, alpha " << alpha << " beta " << beta;
    }
  }
}

TEST(Step, AFixedNewtonStepThatWouldBlowUpIsTakenByTheMinimiserAndSaysSo) {
  test::TestModel m;
  ASSERT_NE(m.model, nullptr);
  const int r = m.info.r;
  for (qv_integrator integrator : {QV_INTEGRATOR_IMPLICIT_NEWMARK, QV_INTEGRATOR_BACKWARD_EULER}) {
    qv_instance_config config;
    qv_instance_config_init(&config, m.model);
    config.integrator = integrator;
    config.solver = QV_SOLVER_NEWTON;
    config.newton_iterations = 1;
    config.max_displacement = 0.01;
    Instance inst(m.model, config), minimizing(m.model, config);
    const double shove[3] = {0, 0, -1e9};
    qv_instance_add_vertex_force(inst.s, m.tipVertex(), shove);
    EXPECT_NE(qv_instance_step(inst.s), QV_STEP_RESET);
    qv_step_report report;
    qv_instance_last_step(inst.s, &report);
    EXPECT_EQ(report.minimized, 1) << qv_integrator_name(integrator);
    // Exactly the minimising solver's step from the same start, under the same load.
    qv_instance_config alone = config;
    alone.solver = QV_SOLVER_MINIMIZE;
    alone.newton_iterations = 8;
    Instance reference(m.model, alone);
    qv_instance_add_vertex_force(reference.s, m.tipVertex(), shove);
    qv_instance_step(reference.s);
    EXPECT_EQ(state(inst.s, r), state(reference.s, r)) << qv_integrator_name(integrator);
    EXPECT_GT(state(inst.s, r).norm(), 0.0);
    // Then, without the shove, fixed Newton steps again.
    EXPECT_NE(qv_instance_step(inst.s), QV_STEP_RESET);
    EXPECT_TRUE(state(inst.s, r).allFinite());

    // From a state fixed Newton steps bent under gravity, the minimiser budgets from that state's
    // energy: let go (no load: the budget binds), its step equals the minimiser's from the same
    // state set by hand. maxQ = 0 makes the fixed Newton step hand the step over.
    qv_instance_config defaults;
    qv_instance_config_init(&defaults, m.model);
    config.max_displacement = defaults.max_displacement;
    Instance bent(m.model, config), same(m.model, alone);
    const double g[3] = {0, 0, -QV_STANDARD_GRAVITY};
    qv_instance_set_gravity(bent.s, g);
    qv_instance_set_gravity(same.s, g);
    for (int step = 0; step < 20; ++step) {
      ASSERT_NE(qv_instance_step(bent.s), QV_STEP_RESET);
      qv_instance_last_step(bent.s, &report);
      ASSERT_EQ(report.minimized, 0) << "step " << step;
    }
    Eigen::VectorXd q(r), v(r), a(r);
    qv_instance_get_state(bent.s, q.data(), v.data(), a.data());
    ASSERT_GT(q.norm(), 0.0);
    qv_instance_set_state(same.s, q.data(), v.data(), a.data());
    // A snapshot of it carries E(q), which a minimising instance restored from it budgets from as
    // after set_state, and the slack the fixed Newton account leaves (the budget does not bind here,
    // under gravity): restored, the two step alike.
    std::vector<char> snapshot(qv_instance_snapshot_size(bent.s));
    qv_instance_save_snapshot(bent.s, snapshot.data());
    Instance restored(m.model, alone), fresh(m.model, alone);
    ASSERT_EQ(qv_instance_restore_snapshot(restored.s, snapshot.data(), snapshot.size()), QV_OK);
    qv_instance_set_state(fresh.s, q.data(), v.data(), a.data());
    for (qv_instance* s : {restored.s, fresh.s}) qv_instance_step(s);
    EXPECT_EQ(state(restored.s, r), state(fresh.s, r)) << qv_integrator_name(integrator);
    const double none[3] = {0, 0, 0};
    qv_instance_set_gravity(bent.s, none);
    qv_instance_set_gravity(same.s, none);
    bent.s->maxQ = 0;
    EXPECT_NE(qv_instance_step(bent.s), QV_STEP_RESET);
    qv_instance_step(same.s);
    qv_instance_last_step(bent.s, &report);
    EXPECT_EQ(report.minimized, 1) << qv_integrator_name(integrator);
    Eigen::VectorXd q2(r), v2(r);
    qv_instance_get_state(bent.s, q.data(), v.data(), nullptr);
    qv_instance_get_state(same.s, q2.data(), v2.data(), nullptr);
    EXPECT_EQ(q, q2) << qv_integrator_name(integrator);
    EXPECT_EQ(v, v2) << qv_integrator_name(integrator);
  }
}

// The load the runtime bench steps under (bench/runtime.cpp, Step): gravity plus twice its pull on
// the first coordinate, flipping every half second. It bends the soft bar until its stiffness turns
// indefinite. One fixed Newton iteration from the last acceleration's guess used to throw it past
// max_displacement at the flips (171 resets in 6000 steps) and, with the minimiser taking those
// steps, still swung it to 9 times the minimiser's largest |q|. From the state, within the energy
// budget (fixed_newton.h), no step resets and it swings as far as the minimiser's.
TEST(Step, FixedNewtonUnderAFlippingPushSwingsAsTheMinimiser) {
  test::TestModel m;
  ASSERT_NE(m.model, nullptr);
  const int r = m.info.r;
  double largest[2] = {0, 0};
  for (qv_solver solver : {QV_SOLVER_NEWTON, QV_SOLVER_MINIMIZE}) {
    qv_instance_config config;
    qv_instance_config_init(&config, m.model);
    config.solver = solver;
    if (solver == QV_SOLVER_NEWTON) config.newton_iterations = 1;
    Instance inst(m.model, config);
    const double g[3] = {0, 0, -QV_STANDARD_GRAVITY};
    qv_instance_set_gravity(inst.s, g);
    std::vector<double> push(r, 0.0);
    const double amplitude = 2 * QV_STANDARD_GRAVITY * std::fabs(qv_model_gravity(m.model)[2 * r]);
    const int period = static_cast<int>(std::lround(0.5 / config.time_step));
    int minimized = 0;
    double smallestAfterAFlip = 1e300, removed = 0;
    for (int step = 0; step < 1200; ++step) {
      push[0] = (step / period) % 2 ? amplitude : -amplitude;
      qv_instance_add_reduced_force(inst.s, push.data());
      ASSERT_NE(qv_instance_step(inst.s), QV_STEP_RESET) << "step " << step;
      qv_step_report report;
      qv_instance_last_step(inst.s, &report);
      minimized += report.minimized;
      removed += report.energy_removed;
      const double size = state(inst.s, r).norm();
      largest[solver] = std::max(largest[solver], size);
      if (step % period == 0 && step > 0) smallestAfterAFlip = std::min(smallestAfterAFlip, size);
    }
    EXPECT_TRUE(state(inst.s, r).allFinite());
    EXPECT_GT(smallestAfterAFlip, 0.0) << "back at rest right after a flip: a reset";
    std::printf("%s: largest |q| %.3g; %d of 1200 steps minimised; %.3g J taken out by the budget\n", qv_solver_name(solver),
                largest[solver], minimized, removed);
  }
  EXPECT_LT(largest[QV_SOLVER_NEWTON], 1.5 * largest[QV_SOLVER_MINIMIZE]);
  EXPECT_GT(largest[QV_SOLVER_NEWTON], 0.5 * largest[QV_SOLVER_MINIMIZE]);
}

// A fixed Newton instance's snapshot carries its energy account (fixed_newton.h: the allowance,
// where the last step started, the exact end checks left). Under the flipping push the budget takes
// energy out; a fresh instance restored from a snapshot taken mid-way repeats the steps bit for bit.
TEST(Step, AFixedNewtonInstanceRestoredFromItsSnapshotRepeatsItsStepsBitForBit) {
  test::TestModel m;
  ASSERT_NE(m.model, nullptr);
  const int r = m.info.r;
  qv_instance_config config;
  qv_instance_config_init(&config, m.model);
  config.solver = QV_SOLVER_NEWTON;
  config.newton_iterations = 1;
  const double g[3] = {0, 0, -QV_STANDARD_GRAVITY};
  const double amplitude = 2 * QV_STANDARD_GRAVITY * std::fabs(qv_model_gravity(m.model)[2 * r]);
  const int period = static_cast<int>(std::lround(0.5 / config.time_step));
  double removed = 0;
  const auto run = [&](qv_instance* s, int from, int to) {
    std::vector<double> push(r, 0.0);
    for (int step = from; step < to; ++step) {
      push[0] = (step / period) % 2 ? amplitude : -amplitude;
      qv_instance_add_reduced_force(s, push.data());
      qv_instance_step(s);
      qv_step_report report;
      qv_instance_last_step(s, &report);
      removed += report.energy_removed;
    }
  };
  // Saved two steps after a flip of the push, and while the account holds exact end checks (the push
  // flipped at 690, and the next step drew the state back).
  for (const int saved : {632, 700}) {
    Instance a(m.model, config), b(m.model, config);
    qv_instance_set_gravity(a.s, g);
    qv_instance_set_gravity(b.s, g);
    run(a.s, 0, saved);
    if (saved == 700) {
      ASSERT_GT(a.s->exactEndChecks, 0);
    }
    std::vector<char> snapshot(qv_instance_snapshot_size(a.s));
    qv_instance_save_snapshot(a.s, snapshot.data());
    // The account itself, which the steps below read only where the budget binds before the loads
    // change again.
    const double allowance = a.s->elasticAllowance, previousElastic = a.s->previousElastic;
    const std::vector<double> previousQ(a.s->previousQ, a.s->previousQ + r);
    const int checks = a.s->exactEndChecks;
    removed = 0;
    run(a.s, saved, 1200);
    EXPECT_GT(removed, 0.0) << "the budget must act while the steps are repeated";
    ASSERT_EQ(qv_instance_restore_snapshot(b.s, snapshot.data(), snapshot.size()), QV_OK);
    EXPECT_EQ(b.s->elasticAllowance, allowance);
    EXPECT_EQ(b.s->previousElastic, previousElastic);
    EXPECT_EQ(std::vector<double>(b.s->previousQ, b.s->previousQ + r), previousQ);
    EXPECT_EQ(b.s->exactEndChecks, checks);
    run(b.s, saved, 1200);
    std::vector<double> sa(3 * r), sb(3 * r);
    qv_instance_get_state(a.s, sa.data(), sa.data() + r, sa.data() + 2 * r);
    qv_instance_get_state(b.s, sb.data(), sb.data() + r, sb.data() + 2 * r);
    EXPECT_EQ(0, std::memcmp(sa.data(), sb.data(), sizeof(double) * sa.size())) << "saved at step " << saved;
  }
}

TEST(Step, DeterministicAndStateRoundTrips) {
  test::TestModel m;
  ASSERT_NE(m.model, nullptr);
  const int r = m.info.r;
  qv_instance_config config;
  qv_instance_config_init(&config, m.model);
  Instance a(m.model, config), b(m.model, config);
  const double g[3] = {0, -9.81, 0}, push[3] = {1, 2, -3};
  qv_instance_set_gravity(a.s, g);
  qv_instance_set_gravity(b.s, g);
  std::vector<double> saved(qv_instance_snapshot_size(a.s) / sizeof(double));
  for (int step = 0; step < 200; ++step) {
    for (auto* s : {a.s, b.s}) qv_instance_add_vertex_force(s, m.tipVertex(), push);
    qv_instance_step(a.s);
    qv_instance_step(b.s);
    if (step == 100) qv_instance_save_snapshot(a.s, saved.data());
  }
  std::vector<double> sa(3 * r), sb(3 * r);
  qv_instance_get_state(a.s, sa.data(), sa.data() + r, sa.data() + 2 * r);
  qv_instance_get_state(b.s, sb.data(), sb.data() + r, sb.data() + 2 * r);
  EXPECT_EQ(0, std::memcmp(sa.data(), sb.data(), sizeof(double) * sa.size()));  // bit-identical
  // Rewind b to step 100 and replay: the same bits again.
  EXPECT_EQ(qv_instance_restore_snapshot(b.s, saved.data(), saved.size() * sizeof(double) - 1), QV_ERROR_INVALID_ARGUMENT);
  // A damping stiffness that is not positive definite (it would add energy) is refused, and b is
  // left as it was. D's upper triangle ends with its (r, r) entry, before the last step's r forces,
  // the load-changed flag and the fixed Newton account (4 + r values) that end the snapshot.
  std::vector<double> spoiled = saved;
  const size_t lastForces = spoiled.size() - 2 * r - 4;
  spoiled[lastForces - 1] = -1;
  EXPECT_EQ(qv_instance_restore_snapshot(b.s, spoiled.data(), spoiled.size() * sizeof(double)), QV_ERROR_INVALID_ARGUMENT);
  // So is one with a value that is not finite (the account's last), but for the last step's forces,
  // where one only marks a change (a step that reset keeps them).
  spoiled = saved;
  spoiled.back() = NAN;
  EXPECT_EQ(qv_instance_restore_snapshot(b.s, spoiled.data(), spoiled.size() * sizeof(double)), QV_ERROR_INVALID_ARGUMENT);
  spoiled = saved;
  spoiled[lastForces] = NAN;
  Instance c(m.model, config);
  EXPECT_EQ(qv_instance_restore_snapshot(c.s, spoiled.data(), spoiled.size() * sizeof(double)), QV_OK);
  qv_instance_get_state(b.s, sb.data(), sb.data() + r, sb.data() + 2 * r);
  EXPECT_EQ(0, std::memcmp(sa.data(), sb.data(), sizeof(double) * sa.size()));
  ASSERT_EQ(qv_instance_restore_snapshot(b.s, saved.data(), saved.size() * sizeof(double)), QV_OK);
  for (int step = 101; step < 200; ++step) {
    qv_instance_add_vertex_force(b.s, m.tipVertex(), push);
    qv_instance_step(b.s);
  }
  qv_instance_get_state(b.s, sb.data(), sb.data() + r, sb.data() + 2 * r);
  EXPECT_EQ(0, std::memcmp(sa.data(), sb.data(), sizeof(double) * sa.size()));
}

// The budget compares each step's loads with the last step's (a change forfeits the slack the
// discretisation lost): the snapshot carries the last step's, so a rewound instance replays the
// same bits whatever it was pushed by in between. Undamped and swinging far, where the slack is
// won back.
TEST(Step, ASnapshotCarriesTheLoadsTheBudgetComparesWith) {
  test::TestModel m;
  ASSERT_NE(m.model, nullptr);
  const int r = m.info.r, tip = m.tipVertex();
  qv_instance_config config;
  qv_instance_config_init(&config, m.model);
  config.rayleigh_alpha = config.rayleigh_beta = 0;
  Instance a(m.model, config), b(m.model, config);
  const double push[3] = {0, 0, -20}, other[3] = {0, 5, 0};
  for (int step = 0; step < 50; ++step)
    for (auto* s : {a.s, b.s}) {
      qv_instance_add_vertex_force(s, tip, push);
      qv_instance_step(s);
    }
  std::vector<char> saved(qv_instance_snapshot_size(a.s));
  qv_instance_save_snapshot(a.s, saved.data());
  qv_instance_add_vertex_force(b.s, tip, other);
  qv_instance_step(b.s);
  ASSERT_EQ(qv_instance_restore_snapshot(b.s, saved.data(), saved.size()), QV_OK);
  for (int step = 0; step < 100; ++step) {
    for (auto* s : {a.s, b.s}) {
      qv_instance_add_vertex_force(s, tip, push);
      qv_instance_step(s);
    }
    ASSERT_EQ(state(a.s, r), state(b.s, r)) << "step " << step;
  }
}

TEST(Step, DragSpringPullsAVertexToItsTarget) {
  test::TestModel m;
  ASSERT_NE(m.model, nullptr);
  qv_instance_config config;
  qv_instance_config_init(&config, m.model);
  config.rayleigh_alpha = 20;
  Instance inst(m.model, config);
  const int tip = m.tipVertex();
  const Eigen::Vector3d X = m.mesh.vertices[tip];
  const double target[3] = {X.x(), X.y(), X.z() + 0.02};
  ASSERT_EQ(qv_instance_set_constraint(inst.s, 0, &tip, 1, target, 1e4), QV_OK);
  for (int step = 0; step < 1000; ++step) qv_instance_step(inst.s);
  float p[3];
  ASSERT_EQ(qv_instance_positions_of(inst.s, &tip, 1, p), QV_OK);
  EXPECT_GT(p[2] - X.z(), 0.5 * 0.02);  // a stiff spring wins most of the way
  EXPECT_LE(p[2] - X.z(), 0.02 + 1e-6);
  qv_instance_clear_constraint(inst.s, 0);
  for (int step = 0; step < 1000; ++step) qv_instance_step(inst.s);
  ASSERT_EQ(qv_instance_positions_of(inst.s, &tip, 1, p), QV_OK);
  EXPECT_NEAR(p[2], X.z(), 1e-4);  // released: back to rest
}

// Linear modal dynamics (QV_ELASTICITY_LINEAR): the same Newmark scheme on q'' + K(0) q = f, with K(0)
// taken from the full-space FEM; and, unlike StVK, a stretch that grows with the load squared
// is absent: doubling the load doubles the response exactly.
TEST(Step, LinearModalDynamicsIsExactlyLinear) {
  test::TestModel m;
  ASSERT_NE(m.model, nullptr);
  const int r = m.info.r, tip = m.tipVertex();
  qv_instance_config config;
  qv_instance_config_init(&config, m.model);
  config.elasticity = QV_ELASTICITY_LINEAR;
  config.rayleigh_alpha = config.rayleigh_beta = 0;
  const double h = config.time_step;
  Eigen::VectorXd zero = Eigen::VectorXd::Zero(r), R;
  Eigen::MatrixXd K0;
  m.exact(zero, R, K0);
  std::vector<Eigen::VectorXd> finals;
  for (double scale : {1.0, 2.0}) {
    Instance inst(m.model, config);
    const double pull[3] = {0, 0, -20.0 * scale};  // large enough that StVK would not be linear
    const Eigen::VectorXd f = m.U.middleRows(3 * tip, 3).transpose() * Eigen::Map<const Eigen::Vector3d>(pull);
    Eigen::VectorXd q = zero, v = zero, a = zero;
    const Eigen::MatrixXd A = Eigen::MatrixXd::Identity(r, r) + 0.25 * h * h * K0;
    for (int step = 0; step < 100; ++step) {
      qv_instance_add_vertex_force(inst.s, tip, pull);
      ASSERT_NE(qv_instance_step(inst.s), QV_STEP_RESET);
      const Eigen::VectorXd next = A.ldlt().solve(f - K0 * (q + h * v + 0.25 * h * h * a));
      q += h * v + 0.25 * h * h * (a + next);
      v += 0.5 * h * (a + next);
      a = next;
    }
    EXPECT_LT((state(inst.s, r) - q).norm(), 1e-9 * q.norm());
    finals.push_back(state(inst.s, r));
  }
  EXPECT_LT((finals[1] - 2 * finals[0]).norm(), 1e-12 * finals[1].norm());
}
