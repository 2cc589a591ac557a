// Central differences as velocity Verlet: explicit, stable below qv_instance_stable_time_step().
// Damping uses the predicted end-of-step velocity, so it stays explicit.
#include "../dynamics.h"
#include "integrator.h"

namespace quiver::rt {

qv_step_status stepCentralDifferences(qv_instance& s) {
  const double h = s.config.time_step;
  const int r = s.r;
  double *q = s.q, *v = s.v, *a = s.a;
  for (int i = 0; i < r; ++i) q[i] += h * v[i] + 0.5 * h * h * a[i];
  evaluateForces(s, q);
  for (int i = 0; i < r; ++i) s.end.v[i] = v[i] + h * a[i];
  dampingForces(s, s.end.v, s.work.damping);
  for (int i = 0; i < r; ++i) s.end.a[i] = s.loads.external(i) - s.work.force[i] - s.work.damping[i];
  for (int i = 0; i < r; ++i) {
    v[i] += 0.5 * h * (a[i] + s.end.a[i]);
    a[i] = s.end.a[i];
  }
  return QV_STEP_OK;
}

} // namespace quiver::rt
