// Backward Euler: first order and numerically damped. The minimising solver
// (incremental_potential.h) by default; QV_SOLVER_NEWTON: Newton on the end-of-step velocity,
// from zero, which ends the step at q (fixed_newton.h).
#include <cstring>

#include "../dynamics.h"
#include "fixed_newton.h"
#include "incremental_potential.h"

namespace quiver::rt {

namespace {

qv_step_status minimizing(qv_instance& s) {
  const double h = s.config.time_step;
  const int r = s.r;
  double *q = s.q, *v = s.v, *a = s.a;
  for (int i = 0; i < r; ++i) {
    s.work.predictor[i] = s.end.q[i] = q[i] + h * v[i];  // qt, and the guess
    s.work.predictorVelocity[i] = v[i];
  }
  const qv_step_status status = minimizeStep(s, backwardEulerPredictor(h));
  for (int i = 0; i < r; ++i) {
    a[i] = (s.end.v[i] - v[i]) / h;
    v[i] = s.end.v[i];
  }
  std::memcpy(q, s.end.q, sizeof(double) * r);
  return status;
}

} // namespace

qv_step_status stepBackwardEuler(qv_instance& s) {
  if (s.config.solver == QV_SOLVER_MINIMIZE) return minimizing(s);
  const double h = s.config.time_step;
  const int r = s.r;
  double budget;
  const double* J = beginFixedNewton(s, budget);
  const double *q = s.q, *v = s.v;
  std::memset(s.end.v, 0, sizeof(double) * r);  // the first iteration at q itself
  for (int it = 0; it < s.config.newton_iterations; ++it, ++s.lastStep.newton_iterations) {
    for (int i = 0; i < r; ++i) s.end.q[i] = q[i] + h * s.end.v[i];
    if (it > 0) J = evaluateForces(s, s.end.q);
    dampingForces(s, s.end.v, s.work.damping);
    for (int i = 0; i < r; ++i)
      s.work.correction[i] = -((s.end.v[i] - v[i]) + h * (s.work.damping[i] + s.work.force[i] - s.loads.external(i)));
    if (!solveNewton(s, J, h, h * h)) return minimizedInstead(s, minimizing, it == 0);
    for (int i = 0; i < r; ++i) s.end.v[i] += s.work.correction[i];
  }
  for (int i = 0; i < r; ++i) {
    s.end.a[i] = (s.end.v[i] - v[i]) / h;
    s.end.q[i] = q[i] + h * s.end.v[i];
  }
  return endFixedNewton(s, budget, minimizing);
}

} // namespace quiver::rt
