#include "fixed_newton.h"

#include <cmath>
#include <cstring>

#include "../dynamics.h"
#include "../elasticity.h"

namespace quiver::rt {

namespace {

// After a step's end was drawn back toward its start, this many steps hold their ends to the budget
// at once, at one more evaluation each: where one iteration overshoots that far, it tends to again.
constexpr int kExactEndChecks = 60;

// Settles the account with E(q) (s.elasticEnergyAtState) at this step's loads: a shortfall is slack;
// an excess beyond rounding is taken out as the minimiser's budget takes it out (holdToBudget()),
// with the previous step's start in the role of the start, or, where the loads changed since (its
// potential under them says nothing of the budget), from the velocity alone. Returns whether q
// moved (then, as where the minimiser's step is held back, with no acceleration).
bool settleEnergyAccount(qv_instance& s, bool loadsChanged) {
  double kinetic = 0;
  for (int i = 0; i < s.r; ++i) kinetic += 0.5 * s.v[i] * s.v[i];
  const double excess = s.elasticEnergyAtState - s.elasticAllowance;
  const double roundoff = 1e-12 * (std::fabs(s.elasticEnergyAtState) + std::fabs(s.elasticAllowance) + kinetic);
  if (!(excess > roundoff)) {
    s.energySlack = std::fmax(-excess, 0.0);
    return false;
  }
  s.energySlack = 0;
  const double budget = stepEnergy(s, s.q, s.v, s.elasticEnergyAtState) - excess;
  // From q itself the position holds no more than the start: only the velocity gives.
  const double* start = loadsChanged ? s.q : s.previousQ;
  const double startElastic = loadsChanged ? s.elasticEnergyAtState : s.previousElastic;
  if (!holdToBudget(s, budget, start, startElastic, s.q, s.v, s.elasticEnergyAtState, s.lastStep)) return false;
  std::memset(s.a, 0, sizeof(double) * s.r);
  s.exactEndChecks = kExactEndChecks;
  return true;
}

} // namespace

const double* beginFixedNewton(qv_instance& s, double& budget) {
  elasticityAt(s, s.q, &s.elasticEnergyAtState, s.work.force);
  const double* J = s.loads.addStateForces(s.q, s.work.force);
  const bool loadsChanged = s.loads.changedSinceLastStep();
  if (settleEnergyAccount(s, loadsChanged)) {  // drawn back: the step starts from there
    elasticityAt(s, s.q, &s.elasticEnergyAtState, s.work.force);
    J = s.loads.addStateForces(s.q, s.work.force);
  }
  // As the minimiser's (MinimizeTask::begin()): what was lost under other loads is not owed.
  if (loadsChanged) s.energySlack = 0;
  budget = stepEnergy(s, s.q, s.v, s.elasticEnergyAtState) + s.energySlack;
  return J;
}

qv_step_status minimizedInstead(qv_instance& s, StepFunction minimizing, bool stiffnessAtState) {
  const qv_step_report settled = s.lastStep;  // what beginFixedNewton() took out
  s.lastStep = qv_step_report{};
  s.lastStep.minimized = 1;
  // A group's preset evaluation is not whole once D below overwrites its stiffness.
  s.work.presetValid = false;
  s.work.presetFactor = LaneFactor{};
  // Its damping starts from this state, as after qv_instance_set_state: fixed Newton steps keep no D.
  dampAt(s, s.q, stiffnessAtState, s.dampingStiffness);
  const qv_step_status status = minimizing(s);
  s.lastStep.energy_removed += settled.energy_removed;
  s.lastStep.held_back |= settled.held_back;
  s.openEnergyAccount(s.elasticEnergyAtState);
  return status;
}

qv_step_status endFixedNewton(qv_instance& s, double budget, StepFunction minimizing) {
  if (!s.withinBounds(s.end.q, s.end.v, s.end.a)) return minimizedInstead(s, minimizing, false);
  const int r = s.r;
  // Damping with the last iterate's K, as the iterations damped.
  budget -= dampingShare(s);
  if (s.exactEndChecks > 0) {
    --s.exactEndChecks;
    double elastic = elasticEnergy(*s.model, s.config.elasticity, s.end.q, s.work.polynomialScratch);
    if (holdToBudget(s, budget, s.q, s.elasticEnergyAtState, s.end.q, s.end.v, elastic, s.lastStep))
      std::memset(s.end.a, 0, sizeof(double) * r);
  }
  s.elasticAllowance = budget - stepEnergy(s, s.end.q, s.end.v, 0.0);
  std::memcpy(s.previousQ, s.q, sizeof(double) * r);
  s.previousElastic = s.elasticEnergyAtState;
  std::memcpy(s.q, s.end.q, sizeof(double) * r);
  std::memcpy(s.v, s.end.v, sizeof(double) * r);
  std::memcpy(s.a, s.end.a, sizeof(double) * r);
  return QV_STEP_OK;
}

} // namespace quiver::rt
