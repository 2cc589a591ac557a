#pragma once
// Implicit steps as minimisation (QV_SOLVER_MINIMIZE). Implicit Newmark (beta = 1/4, gamma = 1/2)
// and backward Euler both make the end-of-step position x a stationary point of
//   Phi(x) = w/2 |x - qt|^2 + E(x) + S(x) - f^T x + 1/(2s) v(x)^T C v(x),   v(x) = v0 + s (x - qt),
// with M = I, E the elastic energy, S the state forces' potential (loads.h), f this step's constant
// forces and C = alpha I + beta D, D the stiffness K(q) at the step's start, shifted to positive
// definite where it is not (lagged Rayleigh damping, as in Li et al. 2020, IPC: a potential that is
// never negative, and which damps a bent object's motion as K(x) does; the rest stiffness K(0)
// damped large rotations several times too much, bench/README.md). grad Phi = 0 is the
// integrator's own equation with C held through the step; its Hessian is w I + K(x) + J + s C.
// Each step's predictor:
//   Newmark:        qt = q + h v + h^2/4 a,  w = 4/h^2,  v0 = v + h/2 a,  s = 2/h
//   backward Euler: qt = q + h v,            w = 1/h^2,  v0 = v,          s = 1/h
// Newton on Phi, the Hessian shifted to positive definite where K(x) is not, backtracking on Phi
// (Armijo), until |grad Phi| <= newton_tolerance x (|w (x - qt)| + |R + S'| + |f| + |C v|) or
// newton_iterations. Then the energy budget: with H = |v|^2/2 + E + S - f^T q at this step's loads,
// a step may not end with more H than it began with, plus the slack earlier steps' discretisation
// lost since the loads last changed (the trapezoidal rule trades energy back and forth on a
// nonlinear model; without the slack the budget would damp it), less what damping dissipates. What the integrator would add beyond
// it is taken out of the velocity (qv_step_report::energy_removed). So without loads and damping H
// never exceeds its first value, and under bounded loads the state stays bounded. Last, D for the
// next step from K at the end.
#include <cmath>

#include "../instance.h"

namespace quiver::rt {

struct StepPredictor {
  double w;  // inertia weight
  double s;  // dv/dx
  double h;  // the time step
};

inline StepPredictor newmarkPredictor(double h) { return {4 / (h * h), 2 / h, h}; }
inline StepPredictor backwardEulerPredictor(double h) { return {1 / (h * h), 1 / h, h}; }
// Of an implicit integrator's steps (backward Euler's or implicit Newmark's).
inline StepPredictor implicitPredictor(const qv_instance_config& c) {
  return c.integrator == QV_INTEGRATOR_BACKWARD_EULER ? backwardEulerPredictor(c.time_step) : newmarkPredictor(c.time_step);
}

// Phi's Hessian w I + K(x) + J + s C, the matrix of each Newton direction (before any shift);
// fused explicitly, as newtonSystem() (dynamics.h).
inline SystemScales minimizerSystem(const qv_instance& s, const StepPredictor& p) {
  return {1.0, 1.0, p.s * s.config.rayleigh_beta, std::fma(p.s, s.config.rayleigh_alpha, p.w)};
}

// The most Newton iterations of a minimising step: newton_iterations (by default
// kMinimizerIterations), or kMinimizerIterations for a QV_SOLVER_NEWTON step it took over
// (fixed_newton.h, minimizedInstead()), where newton_iterations counts fixed iterations.
constexpr int kMinimizerIterations = 8;
inline int maxIterations(const qv_instance& s) {
  return s.config.solver == QV_SOLVER_MINIMIZE ? s.config.newton_iterations : kMinimizerIterations;
}

// Phi at one iterate, the force scale of its convergence test and the state forces' Jacobian, and
// whether K there is known to be positive definite (elasticityAt(), dynamics.h).
struct PhiPoint {
  double phi = 0, scale = 0;
  const double* jacobian = nullptr;
  bool definite = false;
};

// One minimising step in parts between its evaluations, so that a group (step_many.h) can
// evaluate its members' points together: begin(), then, while pending() names a point, resume()
// (which evaluates there, or takes the group's preset evaluation of exactly that point) until
// pending() is null, then status(). Plain data: a group keeps a few and moves them between lanes.
// A Newton direction in the group's factor is a part of its own, between two resume() calls: its
// right-hand side is in s.work.correction and awaitedSolve() names the factor; the group may solve
// it there and call solved(), else the next resume() solves it. Either way before the group
// evaluates again (pending() still names the point already evaluated; the factor lives in the
// group's scratch).
class MinimizeTask {
public:
  // From the guess in s.end.q, with qt in s.work.predictor and v0 in s.work.predictorVelocity.
  void begin(qv_instance& s, const StepPredictor& predictor);
  const double* pending() const { return phase_ == Phase::Done ? nullptr : point_; }
  void resume();
  LaneFactor awaitedSolve() const { return phase_ == Phase::Solve ? factor_ : LaneFactor{}; }
  void solved() { factor_ = LaneFactor{}; }
  // Once done: s.end.q is x and s.end.v is v(x) after the energy budget.
  qv_step_status status() const { return status_; }

private:
  enum class Phase { First, Solve, Trial, Restore, Done };
  void iterate();   // at an accepted iterate: stop, or a Newton direction
  void step();      // along the direction in s.work.correction: its first trial point
  void trialPoint();  // s.work.trial at length_ along it, kept in the box
  void finish();    // the energy budget
  qv_instance* s_ = nullptr;
  StepPredictor p_{};
  Phase phase_ = Phase::Done;
  const double* point_ = nullptr;  // where resume() evaluates
  int iteration_ = 0, cut_ = 0;
  // Every iterate stays in the box |x_i| <= box_ = max(maxQ, |q|_inf at the start): a model whose
  // energy is not bounded below (a damaged or crafted file) would run off to infinity and reset.
  // A baked model's steps never reach it (maxQ: 100 model diagonals by default); a state already
  // past maxQ (set from outside) is not pulled in.
  double box_ = 0;
  double budget_ = 0, elastic_ = 0, trialElastic_ = 0, gradient_ = 0, slope_ = 0, roundoff_ = 0, length_ = 0;
  PhiPoint at_, trial_;
  LaneFactor factor_;  // Phase::Solve: the group's factor the direction is solved in, unless solved
  qv_step_status status_ = QV_STEP_OK;
};

// H = |v|^2/2 + E + S - f^T q at this step's loads (v null: the potential alone), E = `elastic`.
double stepEnergy(const qv_instance& s, const double* q, const double* v, double elastic);

// The budget holds: never end a step with more. Where the position x alone holds more, draw it back
// toward `start` (E = startElastic), whose potential is within the budget (or is the budget where
// it holds more), and say so
// (report.held_back, and the return value); the velocity then gets what is left
// (report.energy_removed). `elastic`: E(x), in and out.
bool holdToBudget(qv_instance& s, double budget, const double* start, double startElastic, double* x, double* velocity,
                  double& elastic, qv_step_report& report);

// What damping dissipates over the step from s.v to s.end.v: h v_mid^T C v_mid, C = alpha I + beta K
// (exact for the trapezoidal rule's linear damping; never below zero, should K be indefinite).
double dampingShare(qv_instance& s, const double* K);
double dampingShare(qv_instance& s);  // with K(q) last evaluated (dampingForces(s, v, out))

// begin(), resume() until done, status().
qv_step_status minimizeStep(qv_instance& s, const StepPredictor& predictor);

} // namespace quiver::rt
