#include "dynamics.h"

#include <cstring>

#include "dense_solve.h"
#include "elasticity.h"

namespace quiver::rt {

namespace {

void fillSystem(qv_instance& s, const double* stateJacobian, double c1, double c2) {
  const double alpha = s.config.rayleigh_alpha, beta = s.config.rayleigh_beta;
  const int r = s.r;
  for (int i = 0; i < r; ++i)
    for (int j = 0; j < r; ++j)
      s.work.system[i * r + j] = (c1 * beta + c2) * s.work.stiffness[i * r + j] + c2 * stateJacobian[i * r + j] +
                                 (i == j ? 1.0 + c1 * alpha : 0.0);
}

} // namespace

const double* evaluateForces(qv_instance& s, const double* q) {
  evaluateElasticity(*s.model, s.config.elasticity, q, nullptr, s.work.force, s.work.stiffness,
                     s.work.polynomialScratch);
  return s.loads.addStateForces(q, s.work.force);
}

qv_step_status solveNewton(qv_instance& s, const double* stateJacobian, double c1, double c2) {
  fillSystem(s, stateJacobian, c1, c2);
  // The Cholesky attempt spoils the matrix and the right-hand side, so keep the latter for a second try.
  std::memcpy(s.work.retryRhs, s.work.correction, sizeof(double) * s.r);
  if (choleskySolve(s.work.system, s.work.correction, s.r)) return QV_STEP_OK;
  std::memcpy(s.work.correction, s.work.retryRhs, sizeof(double) * s.r);
  fillSystem(s, stateJacobian, c1, c2);
  return luSolve(s.work.system, s.work.correction, s.work.pivot, s.r) ? QV_STEP_INDEFINITE : QV_STEP_RESET;
}

} // namespace quiver::rt
