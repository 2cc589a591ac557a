#include "dynamics.h"

#include <cstring>

#include "dense_solve.h"
#include "elasticity.h"
#include "simd_dispatch.h"

namespace quiver::rt {

namespace {

// The upper triangle only when `upper` (all Cholesky reads), else the whole matrix (LU).
void fillSystem(qv_instance& s, const double* stateJacobian, double c1, double c2, bool upper) {
  const double alpha = s.config.rayleigh_alpha, beta = s.config.rayleigh_beta;
  const int r = s.r;
  for (int i = 0; i < r; ++i)
    for (int j = upper ? i : 0; j < r; ++j)
      s.work.system[i * r + j] = (c1 * beta + c2) * s.work.stiffness[i * r + j] + c2 * stateJacobian[i * r + j] +
                                 (i == j ? 1.0 + c1 * alpha : 0.0);
}

} // namespace

void elasticityAt(qv_instance& s, const double* q, double* energy, double* force) {
  const bool preset = s.work.presetValid && std::memcmp(q, s.work.presetAt, sizeof(double) * s.r) == 0;
  s.work.presetValid = false;  // only ever the first evaluation: the next is elsewhere
  s.work.presetFactored = s.work.presetFactored && preset;
  if (preset) {
    std::memcpy(force, s.work.presetForce, sizeof(double) * s.r);
    if (energy) *energy = s.work.presetEnergy;
    return;
  }
  evaluateElasticity(*s.model, s.config.elasticity, q, energy, force, s.work.stiffness, s.work.polynomialScratch);
}

const double* evaluateForces(qv_instance& s, const double* q) {
  elasticityAt(s, q, nullptr, s.work.force);
  return s.loads.addStateForces(q, s.work.force);
}

QV_HOT qv_step_status solveNewton(qv_instance& s, const double* stateJacobian, double c1, double c2) {
  const bool factored = s.work.presetFactored && c1 == s.work.presetC1 && c2 == s.work.presetC2;
  s.work.presetFactored = false;
  if (factored) {
    choleskySubstitute(s.work.system, s.work.correction, s.r);
    return QV_STEP_OK;
  }
  fillSystem(s, stateJacobian, c1, c2, true);
  // The Cholesky attempt spoils the matrix and the right-hand side, so keep the latter for a second try.
  std::memcpy(s.work.retryRhs, s.work.correction, sizeof(double) * s.r);
  if (choleskySolve(s.work.system, s.work.correction, s.r)) return QV_STEP_OK;
  std::memcpy(s.work.correction, s.work.retryRhs, sizeof(double) * s.r);
  fillSystem(s, stateJacobian, c1, c2, false);
  return luSolve(s.work.system, s.work.correction, s.work.pivot, s.r) ? QV_STEP_INDEFINITE : QV_STEP_RESET;
}

} // namespace quiver::rt
