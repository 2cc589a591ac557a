#include "dynamics.h"

#include <cstring>

#include "dense_solve.h"
#include "elasticity.h"
#include "simd_dispatch.h"

namespace quiver::rt {

void fillSystem(qv_instance& s, const double* stateJacobian, const SystemScales& scales) {
  const int r = s.r;
  const double* D = s.dampingStiffness;
  const double* K = wholeStiffness(s);
  for (int i = 0; i < r; ++i)
    for (int j = i; j < r; ++j)
      s.work.system[i * r + j] = scales.stiffness * K[i * r + j] +
                                 scales.stateJacobian * stateJacobian[i * r + j] +
                                 scales.dampingStiffness * D[i * r + j] + (i == j ? scales.identity : 0.0);
}

// QV_HOT: its factorisation built as choleskyFactorLanes() is, so that a group's verdict is its own.
QV_HOT void dampWithStiffness(const qv_instance& s, const double* K, double* D, bool definite) {
  const int r = s.r;
  if (definite) {  // the ladder's first rung, which would succeed
    if (D != K) std::memcpy(D, K, sizeof(double) * r * r);
    return;
  }
  const double* K0 = s.model->restStiffness;
  bool finite = true;
  for (int i = 0; i < r * r; ++i) finite = finite && std::isfinite(K[i]);
  if (!finite && K != K0) return dampWithStiffness(s, K0, D);  // the step resets anyway
  double largest = 0;
  for (int i = 0; i < r; ++i) largest = std::fmax(largest, std::fabs(K[i * r + i]));
  if (!(largest > 0)) largest = 1;
  double* trial = s.work.system;  // free between steps, where D is set
  for (int rung = 0; rung <= 40; ++rung) {
    const double mu = rung == 0 ? 0.0 : std::ldexp(1e-6 * largest, 2 * (rung - 1));
    for (int i = 0; i < r; ++i)
      for (int j = i; j < r; ++j) trial[i * r + j] = K[i * r + j] + (i == j ? mu : 0.0);
    if (choleskyFactor(trial, r)) {
      if (D != K) std::memcpy(D, K, sizeof(double) * r * r);
      for (int i = 0; i < r; ++i) D[i * r + i] += mu;
      return;
    }
  }
  // Nothing finite is this far from definite; a positive definite D all the same.
  for (int i = 0; i < r * r; ++i) D[i] = i % (r + 1) == 0 ? largest : 0.0;
}

QV_HOT void dampingForces(const qv_instance& s, const double* K, const double* v, double* out) {
  const int r = s.r;
  const double alpha = s.config.rayleigh_alpha, beta = s.config.rayleigh_beta;
  for (int i = 0; i < r; ++i) out[i] = alpha * v[i];
  for (int j = 0; j < r; ++j) {
    const double* Kj = K + j * r;
    const double vj = v[j];
#pragma omp simd
    for (int i = 0; i < r; ++i) out[i] += beta * Kj[i] * vj;
  }
}

// Along the packed rows: the terms below the diagonal as axpys, the others as row a's dot product,
// in four sums (one vectorised reduction per short row spilled its vector to sum it).
QV_HOT void dampingForces(const qv_instance& s, const double* v, double* out) {
  const double* K = s.work.stiffnessPacked;
  if (!K) return dampingForces(s, s.work.stiffness, v, out);
  const int r = s.r;
  const double alpha = s.config.rayleigh_alpha, beta = s.config.rayleigh_beta;
  for (int i = 0; i < r; ++i) out[i] = 0;
  for (int a = 0; a < r; ++a) {
    const double* row = K + packedUpperIndex(r, a, a) - a;  // row[b] = K_ab, b >= a
    const double va = v[a];
#pragma omp simd
    for (int b = a + 1; b < r; ++b) out[b] += row[b] * va;
    double sum[4] = {row[a] * va, 0, 0, 0};
    int b = a + 1;
    for (; b + 4 <= r; b += 4)
      for (int u = 0; u < 4; ++u) sum[u] += row[b + u] * v[b + u];
    for (; b < r; ++b) sum[0] += row[b] * v[b];
    out[a] += (sum[0] + sum[1]) + (sum[2] + sum[3]);
  }
  for (int i = 0; i < r; ++i) out[i] = alpha * v[i] + beta * out[i];
}

const double* wholeStiffness(const qv_instance& s) {
  if (const double* K = s.work.stiffnessPacked) {
    const int r = s.r;
    for (int a = 0; a < r; ++a) {
      double* row = s.work.stiffness + a * r;
      for (int b = 0; b < a; ++b) row[b] = s.work.stiffness[b * r + a];  // written with row b
      for (int b = a; b < r; ++b) row[b] = K[packedUpperIndex(r, a, b)];
    }
  }
  s.work.stiffnessPacked = nullptr;
  return s.work.stiffness;
}

LaneFactor takePresetFactor(qv_instance& s, const SystemScales& scales) {
  const LaneFactor factor = scales == s.work.presetScales ? s.work.presetFactor : LaneFactor{};
  s.work.presetFactor = LaneFactor{};
  s.work.presetFactorsTaken += factor.A != nullptr;
  return factor;
}

void dampAt(const qv_instance& s, const double* x, bool evaluatedAtX, double* D, bool definite) {
  if (!evaluatedAtX) {
    s.work.stiffnessPacked = nullptr;
    evaluateElasticity(*s.model, s.config.elasticity, x, nullptr, s.work.force, s.work.stiffness, s.work.polynomialScratch);
  }
  dampWithStiffness(s, wholeStiffness(s), D, definite);
}

bool elasticityAt(qv_instance& s, const double* q, double* energy, double* force) {
  const bool preset = s.work.presetValid && std::memcmp(q, s.work.presetAt, sizeof(double) * s.r) == 0;
  s.work.presetValid = false;  // only ever the next evaluation: the one after is elsewhere
  if (!preset) s.work.presetFactor = LaneFactor{};
  s.work.stiffnessPacked = preset ? s.work.presetStiffness : nullptr;
  if (preset) {
    std::memcpy(force, s.work.presetForce, sizeof(double) * s.r);
    if (energy) *energy = s.work.presetEnergy;
    return s.work.presetDefinite;
  }
  evaluateElasticity(*s.model, s.config.elasticity, q, energy, force, s.work.stiffness, s.work.polynomialScratch);
  return false;
}

const double* evaluateForces(qv_instance& s, const double* q) {
  elasticityAt(s, q, nullptr, s.work.force);
  return s.loads.addStateForces(q, s.work.force);
}

QV_HOT bool solveNewton(qv_instance& s, const double* stateJacobian, double c1, double c2) {
  const SystemScales scales = newtonSystem(s, c1, c2);
  if (const LaneFactor factor = takePresetFactor(s, scales); factor.A) {
    choleskySubstitute(factor, s.work.correction, s.r);
    return true;
  }
  fillSystem(s, stateJacobian, scales);
  return choleskySolve(s.work.system, s.work.correction, s.r);
}

} // namespace quiver::rt
