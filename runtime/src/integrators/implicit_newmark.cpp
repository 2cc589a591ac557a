// Implicit Newmark, beta = 1/4, gamma = 1/2 (the trapezoidal rule; Barbic & James 2005). The
// minimising solver (incremental_potential.h) by default; QV_SOLVER_NEWTON: Newton on the
// end-of-step acceleration, from the one that ends the step at q (fixed_newton.h).
#include <cstring>

#include "../dynamics.h"
#include "fixed_newton.h"
#include "incremental_potential.h"

namespace quiver::rt {

StepPredictor beginNewmarkMinimization(qv_instance& s) {
  const double h = s.config.time_step;
  const int r = s.r;
  const double *q = s.q, *v = s.v, *a = s.a;
  for (int i = 0; i < r; ++i) {
    s.work.predictor[i] = q[i] + h * v[i] + 0.25 * h * h * a[i];
    s.work.predictorVelocity[i] = v[i] + 0.5 * h * a[i];
    s.end.q[i] = newmarkGuess(s, i);
  }
  return newmarkPredictor(h);
}

qv_step_status endNewmarkMinimization(qv_instance& s, const StepPredictor& p, qv_step_status status) {
  const int r = s.r;
  for (int i = 0; i < r; ++i) s.end.a[i] = s.lastStep.held_back ? 0.0 : p.w * (s.end.q[i] - s.work.predictor[i]);
  std::memcpy(s.q, s.end.q, sizeof(double) * r);
  std::memcpy(s.v, s.end.v, sizeof(double) * r);
  std::memcpy(s.a, s.end.a, sizeof(double) * r);
  return status;
}

namespace {

qv_step_status minimizing(qv_instance& s) {
  const StepPredictor p = beginNewmarkMinimization(s);
  return endNewmarkMinimization(s, p, minimizeStep(s, p));
}

} // namespace

namespace {

// Iteration `it` of the fixed Newton step up to its solve: the end that s.end.a puts, the forces
// there (evaluated after the first iteration, which is linearised at q), and the right-hand side
// in s.work.correction. Returns J.
const double* newtonRightHandSide(qv_instance& s, int it, const double* J) {
  const double h = s.config.time_step, beta = kNewmarkBeta, gamma = kNewmarkGamma;
  const int r = s.r;
  const double *q = s.q, *v = s.v, *a = s.a;
  for (int i = 0; i < r; ++i) {
    s.end.q[i] = q[i] + h * v[i] + h * h * ((0.5 - beta) * a[i] + beta * s.end.a[i]);
    s.end.v[i] = v[i] + h * ((1 - gamma) * a[i] + gamma * s.end.a[i]);
  }
  if (it > 0) J = evaluateForces(s, s.end.q);
  dampingForces(s, s.end.v, s.work.damping);
  for (int i = 0; i < r; ++i)
    s.work.correction[i] = -(s.end.a[i] + s.work.damping[i] + s.work.force[i] - s.loads.external(i));
  return J;
}

} // namespace

bool beginNewmarkNewton(qv_instance& s, NewmarkNewton& step, qv_step_status& status) {
  step.J = beginFixedNewton(s, step.budget);
  // Soft contacts pin the deformation where they hold it, and the trapezoidal rule then flips its
  // velocity there every step (v' = 2 (q' - q) / h - v): fixed steps rang against a resting bar and,
  // at one or two iterations, fed it until it flew off. The minimiser's energy budget bounds them.
  if (newmarkStepMinimized(s)) {
    status = minimizedInstead(s, minimizing, true);
    return false;
  }
  const double h = s.config.time_step, beta = kNewmarkBeta;
  // The first iteration at q itself: the end-of-step acceleration that puts the end there.
  for (int i = 0; i < s.r; ++i) s.end.a[i] = -(s.v[i] / (beta * h) + (0.5 - beta) / beta * s.a[i]);
  step.J = newtonRightHandSide(s, 0, step.J);
  return true;
}

qv_step_status endNewmarkNewton(qv_instance& s, const NewmarkNewton& step, bool solved) {
  const double h = s.config.time_step, beta = kNewmarkBeta, gamma = kNewmarkGamma;
  const int r = s.r;
  const double *q = s.q, *v = s.v, *a = s.a;
  const double* J = step.J;
  double c1, c2;
  newmarkNewtonScales(s, c1, c2);
  for (int it = 0; it < s.config.newton_iterations; ++it, ++s.lastStep.newton_iterations) {
    if (it > 0) J = newtonRightHandSide(s, it, J);
    if (!(it == 0 && solved) && !solveNewton(s, J, c1, c2)) return minimizedInstead(s, minimizing, it == 0);
    for (int i = 0; i < r; ++i) s.end.a[i] += s.work.correction[i];
  }
  for (int i = 0; i < r; ++i) {
    s.end.q[i] = q[i] + (h * v[i] + h * h * ((0.5 - beta) * a[i] + beta * s.end.a[i]));
    s.end.v[i] = v[i] + h * ((1 - gamma) * a[i] + gamma * s.end.a[i]);
  }
  return endFixedNewton(s, step.budget, minimizing);
}

qv_step_status stepImplicitNewmark(qv_instance& s) {
  if (s.config.solver == QV_SOLVER_MINIMIZE) return minimizing(s);
  NewmarkNewton step;
  qv_step_status status;
  return beginNewmarkNewton(s, step, status) ? endNewmarkNewton(s, step, false) : status;
}

} // namespace quiver::rt
