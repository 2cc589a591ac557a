#include "loads.h"

#include <cstring>

#include "quiver/modal_warping.h"

namespace quiver::rt {

void Loads::carve(BlockCarver& c, int reducedSize, int slotCount, bool flying) {
  r = reducedSize;
  slots = slotCount;
  const size_t rr = static_cast<size_t>(r) * r;
  stepForce = c.take<double>(r);  // the vectors first (qv_instance::carve())
  lastStepForce = c.take<double>(r);
  gravityForce = c.take<double>(r);
  frameForce = c.take<double>(r);
  constraintB = c.take<double>(r);
  constraintK = c.take<double>(rr);
  slotK = c.take<double>(rr * slots);
  slotB = c.take<double>(static_cast<size_t>(r) * slots);
  slotActive = c.take<int>(slots);
  if (flying) stateJacobian = c.take<double>(rr);
}

void Loads::clear() {
  std::memset(stepForce, 0, sizeof(double) * r);
  std::memset(lastStepForce, 0, sizeof(double) * r);
  std::memset(gravityForce, 0, sizeof(double) * r);
  std::memset(frameForce, 0, sizeof(double) * r);
  std::memset(slotActive, 0, sizeof(int) * slots);
  combineConstraints();
}

const double* Loads::addStateForces(const double* q, double* force, double* energy) const {
  double potential = 0;  // q^T Kc q / 2 - bc^T q
  for (int i = 0; i < r && constrained; ++i) {
    double s = -constraintB[i];
    for (int j = 0; j < r; ++j) s += constraintK[i * r + j] * q[j];
    force[i] += s;
    potential += 0.5 * q[i] * (s - constraintB[i]);
  }
  if (!frame) {
    if (energy) *energy = potential;
    return constraintK;
  }
  std::memcpy(stateJacobian, constraintK, sizeof(double) * r * r);
  potential += frame->addCentrifugal(*model, q, force, stateJacobian);
  if (energy) *energy = potential;
  return stateJacobian;
}

void Loads::endStep() {
  std::memcpy(lastStepForce, stepForce, sizeof(double) * r);
  std::memset(stepForce, 0, sizeof(double) * r);
  changed = false;
}

void Loads::continueStep() {
  std::memcpy(lastStepForce, stepForce, sizeof(double) * r);
  changed = false;
}

bool Loads::changedSinceLastStep() const {
  return changed || std::memcmp(stepForce, lastStepForce, sizeof(double) * r) != 0;
}

void Loads::addVertexForce(const qv_model& m, qv_elasticity elasticity, const double* q, int vertex,
                           const double force[3]) {
  double local[3] = {force[0], force[1], force[2]};
  if (elasticity == QV_ELASTICITY_MODAL_WARPING) {  // into the vertex's rotated frame: R(w)^T f, the rotation by -w
    double d[3], w[3];
    m.vertexLinear(vertex, q, d, w);
    const double back[3] = {-w[0], -w[1], -w[2]};
    warping::rotate(back, force, local);
  }
  for (int j = 0; j < r; ++j)
    for (int c = 0; c < 3; ++c) stepForce[j] += m.basisEntry(3 * static_cast<size_t>(vertex) + c, j) * local[c];
}

void Loads::addReducedForce(const double* force) {
  for (int j = 0; j < r; ++j) stepForce[j] += force[j];
}

void Loads::setGravity(const qv_model& m, const double g[3]) {
  changed = true;
  const double* G = m.gravity;  // 3 x r: row a = U^T M e_a
  for (int j = 0; j < r; ++j) gravityForce[j] = G[j] * g[0] + G[r + j] * g[1] + G[2 * r + j] * g[2];
}

void Loads::setConstraint(const qv_model& m, int slot, const int* vertices, int count, const double* targets,
                          double stiffness) {
  double* K = slotK + static_cast<size_t>(slot) * r * r;
  double* b = slotB + static_cast<size_t>(slot) * r;
  std::memset(K, 0, sizeof(double) * r * r);
  std::memset(b, 0, sizeof(double) * r);
  // Per vertex: stiffness k U_v^T U_v, force k U_v^T (U_v q - (target - X_v)).
  for (int k = 0; k < count; ++k) {
    const size_t row = 3 * static_cast<size_t>(vertices[k]);
    for (int c = 0; c < 3; ++c) {
      const double gap = targets[3 * k + c] - m.rest[row + c];
      for (int i = 0; i < r; ++i) {
        const double ui = m.basisEntry(row + c, i);
        b[i] += stiffness * ui * gap;
        for (int j = 0; j < r; ++j) K[i * r + j] += stiffness * ui * m.basisEntry(row + c, j);
      }
    }
  }
  slotActive[slot] = 1;
  changed = true;
  combineConstraints();
}

void Loads::clearConstraint(int slot) {
  changed = true;
  slotActive[slot] = 0;
  combineConstraints();
}

void Loads::combineConstraints() {
  const size_t rr = static_cast<size_t>(r) * r;
  std::memset(constraintK, 0, sizeof(double) * rr);
  std::memset(constraintB, 0, sizeof(double) * r);
  constrained = false;
  for (int s = 0; s < slots; ++s) {
    if (!slotActive[s]) continue;
    constrained = true;
    for (size_t k = 0; k < rr; ++k) constraintK[k] += slotK[s * rr + k];
    for (int i = 0; i < r; ++i) constraintB[i] += slotB[s * r + i];
  }
}

} // namespace quiver::rt
