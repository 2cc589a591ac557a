// Implicit Newmark, beta = 1/4, gamma = 1/2 (the trapezoidal rule; Barbic & James 2005): Newton
// on the end-of-step acceleration, starting from the last one.
#include <cstring>

#include "../dynamics.h"
#include "integrator.h"

namespace quiver::rt {

qv_step_status stepImplicitNewmark(qv_instance& s) {
  const double h = s.config.time_step, beta = 0.25, gamma = 0.5;
  const int r = s.r;
  double *q = s.q, *v = s.v, *a = s.a;
  std::memcpy(s.end.a, a, sizeof(double) * r);
  qv_step_status status = QV_STEP_OK;
  for (int it = 0; it < s.config.newton_iterations; ++it) {
    for (int i = 0; i < r; ++i) {
      s.end.q[i] = q[i] + h * v[i] + h * h * ((0.5 - beta) * a[i] + beta * s.end.a[i]);
      s.end.v[i] = v[i] + h * ((1 - gamma) * a[i] + gamma * s.end.a[i]);
    }
    const double* J = evaluateForces(s, s.end.q);
    for (int i = 0; i < r; ++i)
      s.work.correction[i] = -(s.end.a[i] + dampingForce(s, i, s.end.v) + s.work.force[i] - s.loads.external(i));
    const qv_step_status solved = solveNewton(s, J, gamma * h, beta * h * h);
    if (solved == QV_STEP_RESET) return solved;
    if (solved == QV_STEP_INDEFINITE) status = solved;
    for (int i = 0; i < r; ++i) s.end.a[i] += s.work.correction[i];
  }
  for (int i = 0; i < r; ++i) {
    q[i] += h * v[i] + h * h * ((0.5 - beta) * a[i] + beta * s.end.a[i]);
    v[i] += h * ((1 - gamma) * a[i] + gamma * s.end.a[i]);
    a[i] = s.end.a[i];
  }
  return status;
}

} // namespace quiver::rt
