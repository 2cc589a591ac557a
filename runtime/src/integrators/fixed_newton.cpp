#include "fixed_newton.h"

#include <cmath>
#include <cstring>

#include "../dynamics.h"

namespace quiver::rt {

namespace {

// Settles the account with E(q), the elastic energy at the state: an excess leaves the velocity (all
// of it when the position alone holds more: the step starts from rest), a shortfall is slack.
void settleEnergyAccount(qv_instance& s, double elastic) {
  const double excess = elastic - s.elasticAllowance;
  if (!(excess > 0)) {
    s.energySlack = -excess;
    return;
  }
  s.energySlack = 0;
  double kinetic = 0;
  for (int i = 0; i < s.r; ++i) kinetic += 0.5 * s.v[i] * s.v[i];
  const double keep = excess < kinetic ? std::sqrt((kinetic - excess) / kinetic) : 0.0;
  for (int i = 0; i < s.r; ++i) s.v[i] *= keep;
  s.lastStep.energy_removed = kinetic * (1 - keep * keep);
}

} // namespace

const double* beginFixedNewton(qv_instance& s, double& budget) {
  elasticityAt(s, s.q, &s.elasticEnergyAtState, s.work.force);
  const double* J = s.loads.addStateForces(s.q, s.work.force);
  settleEnergyAccount(s, s.elasticEnergyAtState);
  // As the minimiser's (MinimizeTask::begin()): what was lost under other loads is not owed.
  if (s.loads.changedSinceLastStep()) s.energySlack = 0;
  budget = stepEnergy(s, s.q, s.v, s.elasticEnergyAtState) + s.energySlack;
  return J;
}

qv_step_status minimizedInstead(qv_instance& s, StepFunction minimizing) {
  const double energyRemoved = s.lastStep.energy_removed;  // by beginFixedNewton()
  s.lastStep = qv_step_report{};
  s.lastStep.minimized = 1;
  // A group's preset evaluation is not whole once D below overwrites its stiffness.
  s.work.presetValid = false;
  s.work.presetFactor = LaneFactor{};
  // Its damping starts from this state, as after qv_instance_set_state: fixed Newton steps keep no D.
  s.dampingStiffnessAtState(s.dampingStiffness);
  const qv_step_status status = minimizing(s);
  s.lastStep.energy_removed += energyRemoved;
  s.elasticAllowance = s.elasticEnergyAtState + s.energySlack;
  return status;
}

qv_step_status endFixedNewton(qv_instance& s, double budget, StepFunction minimizing) {
  if (!s.withinBounds(s.end.q, s.end.v, s.end.a)) return minimizedInstead(s, minimizing);
  const int r = s.r;
  // Damping with the last iterate's K, as the iterations damped.
  s.elasticAllowance = budget - dampingShare(s, s.work.stiffness) - stepEnergy(s, s.end.q, s.end.v, 0.0);
  std::memcpy(s.q, s.end.q, sizeof(double) * r);
  std::memcpy(s.v, s.end.v, sizeof(double) * r);
  std::memcpy(s.a, s.end.a, sizeof(double) * r);
  return QV_STEP_OK;
}

} // namespace quiver::rt
