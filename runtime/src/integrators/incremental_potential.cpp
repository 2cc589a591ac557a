#include "incremental_potential.h"

#include <cmath>
#include <cstring>

#include "../dense_solve.h"
#include "../dynamics.h"
#include "../elasticity.h"

namespace quiver::rt {

namespace {

double dot(const double* a, const double* b, int n) {
  double s = 0;
  for (int i = 0; i < n; ++i) s += a[i] * b[i];
  return s;
}

double norm(const double* a, int n) { return std::sqrt(dot(a, a, n)); }

// x clamped to the box |x_i| <= bound (NaN stays NaN, so that non-finite input still resets).
void boxed(int r, double bound, const double* x, double* out) {
  for (int i = 0; i < r; ++i) out[i] = x[i] > bound ? bound : x[i] < -bound ? -bound : x[i];
}

class Minimizer {
public:
  // qt in s.work.predictor, v0 in s.work.predictorVelocity; v(x) into s.end.v.
  Minimizer(qv_instance& s, const StepPredictor& p)
      : s_(s), p_(p), qt_(s.work.predictor), v0_(s.work.predictorVelocity), velocity_(s.end.v), r_(s.r) {}

  // Evaluates Phi at x and leaves its gradient in s.work.gradient, R + S' in s.work.force, K(x) in
  // s.work.stiffness, v(x) in `velocity` and E(x) in `elastic`.
  PhiPoint evaluate(const double* x, double* elastic) {
    PhiPoint pt;
    double E = 0, S = 0;
    pt.definite = elasticityAt(s_, x, &E, s_.work.force);
    pt.jacobian = s_.loads.addStateForces(x, s_.work.force, &S);
    double inertia = 0, external = 0, damping = 0, inertiaNorm = 0, forceNorm = 0, externalNorm = 0, dampingNorm = 0;
    for (int i = 0; i < r_; ++i) velocity_[i] = v0_[i] + p_.s * (x[i] - qt_[i]);
    dampingForces(s_, s_.dampingStiffness, velocity_, s_.work.damping);
    for (int i = 0; i < r_; ++i) {
      const double d = x[i] - qt_[i], f = s_.loads.external(i), cv = s_.work.damping[i];
      inertia += d * d;
      external += f * x[i];
      damping += velocity_[i] * cv;
      s_.work.gradient[i] = p_.w * d + s_.work.force[i] - f + cv;
      inertiaNorm += p_.w * p_.w * d * d;
      forceNorm += s_.work.force[i] * s_.work.force[i];
      externalNorm += f * f;
      dampingNorm += cv * cv;
    }
    pt.phi = 0.5 * p_.w * inertia + E + S - external + damping / (2 * p_.s);
    pt.scale = std::sqrt(inertiaNorm) + std::sqrt(forceNorm) + std::sqrt(externalNorm) + std::sqrt(dampingNorm);
    *elastic = E;
    return pt;
  }

  // Newton direction into s.work.correction, which holds -g: (H + mu I) d = -g, mu the smallest of
  // 0 and a growing ladder that makes the Cholesky factorisation succeed. Returns whether a shift
  // was needed.
  bool direction(const double* jacobian, bool& failed) {
    SystemScales scales = minimizerSystem(s_, p_);
    const double diagonal = scales.identity;
    const double* K = wholeStiffness(s_);
    double largest = 0;
    for (int i = 0; i < r_; ++i) largest = std::fmax(largest, std::fabs(K[i * r_ + i]) + std::fabs(jacobian[i * r_ + i]));
    double mu = 0;
    for (int attempt = 0; attempt < 40; ++attempt) {
      scales.identity = diagonal + mu;
      fillSystem(s_, jacobian, scales);
      if (choleskySolve(s_.work.system, s_.work.correction, r_)) return mu > 0;
      mu = mu > 0 ? 4 * mu : 1e-6 * (largest + diagonal);
    }
    failed = true;
    return true;
  }

private:
  qv_instance& s_;
  const StepPredictor& p_;
  const double* qt_;
  const double* v0_;
  double* velocity_;
  const int r_;
};

} // namespace

double stepEnergy(const qv_instance& s, const double* q, const double* v, double elastic) {
  double kinetic = 0, external = 0, S = 0;
  for (int i = 0; i < s.r; ++i) {
    if (v) kinetic += 0.5 * v[i] * v[i];
    external += s.loads.external(i) * q[i];
  }
  // The state forces' potential alone; the force they add is not needed here.
  std::memset(s.work.stateForceSink, 0, sizeof(double) * s.r);
  s.loads.addStateForces(q, s.work.stateForceSink, &S);
  return kinetic + elastic + S - external;
}

bool holdToBudget(qv_instance& s, double budget, const double* start, double startElastic, double* x, double* velocity,
                  double& elastic, qv_step_report& report) {
  const int r = s.r;
  // Never less than the start holds: where damping's share (counted from the velocity before the
  // hold) or other loads put the start outside, the bisection would end there, frozen. (Its
  // potential is needed only past the budget: most steps end within it.)
  const double endPotential = stepEnergy(s, x, nullptr, elastic);
  double startPotential = 0;
  bool drawBack = false;
  if (endPotential > budget) {
    startPotential = stepEnergy(s, start, nullptr, startElastic);
    drawBack = endPotential > startPotential;
  }
  if (drawBack) {
    budget = std::fmax(budget, startPotential);
    // Bisection on x(t) = start + t (x - start) for the farthest t whose potential is within the budget
    // (t = 0, the start, is); 12 halvings leave t within 1/4096 of it.
    double* farEnd = s.work.segmentEnd;
    std::memcpy(farEnd, x, sizeof(double) * r);
    double within = 0, beyond = 1, withinElastic = startElastic;
    for (int cut = 0; cut < 12; ++cut) {
      const double t = 0.5 * (within + beyond);
      for (int i = 0; i < r; ++i) x[i] = start[i] + t * (farEnd[i] - start[i]);
      const double e = elasticEnergy(*s.model, s.config.elasticity, x, s.work.polynomialScratch);
      if (stepEnergy(s, x, nullptr, e) <= budget) {
        within = t;
        withinElastic = e;
      } else {
        beyond = t;
      }
    }
    for (int i = 0; i < r; ++i) x[i] = start[i] + within * (farEnd[i] - start[i]);
    elastic = withinElastic;
    report.held_back = 1;
  }
  const double energyAfter = stepEnergy(s, x, velocity, elastic);
  if (energyAfter > budget) {
    const double kinetic = 0.5 * dot(velocity, velocity, r), potential = energyAfter - kinetic;
    const double keep = potential < budget && kinetic > 0 ? std::sqrt((budget - potential) / kinetic) : 0.0;
    for (int i = 0; i < r; ++i) velocity[i] *= keep;
    report.energy_removed += kinetic * (1 - keep * keep);
  }
  return drawBack;
}

namespace {

// `damp` puts C v_mid into s.work.damping.
template <class Damp>
double dampingShareBy(qv_instance& s, Damp damp) {
  double* mid = s.work.midpointVelocity;
  for (int i = 0; i < s.r; ++i) mid[i] = 0.5 * (s.v[i] + s.end.v[i]);
  damp(mid, s.work.damping);
  return s.config.time_step * std::fmax(dot(mid, s.work.damping, s.r), 0.0);
}

} // namespace

double dampingShare(qv_instance& s, const double* K) {
  return dampingShareBy(s, [&](const double* v, double* out) { dampingForces(s, K, v, out); });
}

double dampingShare(qv_instance& s) {
  return dampingShareBy(s, [&](const double* v, double* out) { dampingForces(s, v, out); });
}

void MinimizeTask::begin(qv_instance& s, const StepPredictor& p) {
  s_ = &s;
  p_ = p;
  // What the step may end with: what it began with, what earlier steps' discretisation lost and
  // may win back (the trapezoidal rule trades a little energy back and forth on nonlinear models),
  // less what damping dissipates in it (finish()).
  // Loads that changed since the last step start the budget anew: what the discretisation lost
  // under the old loads is not owed under the new ones.
  if (s.loads.changedSinceLastStep()) s.energySlack = 0;
  budget_ = stepEnergy(s, s.q, s.v, s.elasticEnergyAtState) + s.energySlack;
  box_ = s.maxQ;
  for (int i = 0; i < s.r; ++i) box_ = std::fmax(box_, std::fabs(s.q[i]));
  boxed(s.r, box_, s.end.q, s.end.q);
  iteration_ = 0;
  status_ = QV_STEP_OK;
  phase_ = Phase::First;
  point_ = s.end.q;
}

void MinimizeTask::resume() {
  qv_instance& s = *s_;
  const int r = s.r;
  Minimizer minimizer(s, p_);
  switch (phase_) {
    case Phase::First:
      at_ = minimizer.evaluate(s.end.q, &elastic_);
      iterate();
      return;
    case Phase::Trial: {
      trial_ = minimizer.evaluate(s.work.trial, &trialElastic_);
      const bool accepted = trial_.phi <= at_.phi + 1e-4 * length_ * slope_ ||
                            (trial_.phi <= at_.phi + roundoff_ && norm(s.work.gradient, r) < gradient_);
      if (accepted) {
        std::memcpy(s.end.q, s.work.trial, sizeof(double) * r);
        at_ = trial_;
        elastic_ = trialElastic_;
        ++iteration_;
        iterate();
        return;
      }
      ++s.lastStep.line_search_cuts;
      length_ *= 0.5;
      if (++cut_ < 30) {
        trialPoint();
        return;
      }
      phase_ = Phase::Restore;  // no length lowered Phi: x stays, with its forces and velocity
      point_ = s.end.q;
      return;
    }
    case Phase::Solve:
      if (factor_.A) choleskySubstitute(factor_, s.work.correction, r);
      factor_ = LaneFactor{};
      step();
      return;
    case Phase::Restore:
      at_ = minimizer.evaluate(s.end.q, &elastic_);
      finish();
      return;
    case Phase::Done:
      return;
  }
}

void MinimizeTask::iterate() {
  qv_instance& s = *s_;
  const int r = s.r;
  qv_step_report& report = s.lastStep;
  gradient_ = norm(s.work.gradient, r);
  if (!std::isfinite(gradient_) || !std::isfinite(at_.phi)) {  // non-finite input
    status_ = QV_STEP_RESET;
    phase_ = Phase::Done;
    return;
  }
  report.gradient = gradient_ / (at_.scale + 1e-300);
  if (gradient_ <= s.config.newton_tolerance * at_.scale) {
    report.converged = 1;
    return finish();
  }
  if (iteration_ == maxIterations(s)) return finish();
  for (int i = 0; i < r; ++i) s.work.correction[i] = -s.work.gradient[i];
  factor_ = takePresetFactor(s, minimizerSystem(s, p_));
  if (factor_.A) {
    phase_ = Phase::Solve;
    return;
  }
  bool failed = false;
  if (Minimizer(s, p_).direction(at_.jacobian, failed)) status_ = QV_STEP_INDEFINITE;
  if (failed) return finish();
  step();
}

void MinimizeTask::step() {
  qv_instance& s = *s_;
  const int r = s.r;
  ++s.lastStep.newton_iterations;
  slope_ = dot(s.work.gradient, s.work.correction, r);  // < 0: a descent direction
  // Backtracking: the first step length that lowers Phi enough (Armijo), or, near the minimum
  // where Phi's change drowns in its rounding, one that keeps Phi within rounding and lowers the
  // gradient. None, and x stays.
  roundoff_ = 1e-12 * std::fabs(at_.phi);
  length_ = 1;
  cut_ = 0;
  trialPoint();
  phase_ = Phase::Trial;
  point_ = s.work.trial;
}

void MinimizeTask::trialPoint() {
  qv_instance& s = *s_;
  for (int i = 0; i < s.r; ++i) s.work.trial[i] = s.end.q[i] + length_ * s.work.correction[i];
  boxed(s.r, box_, s.work.trial, s.work.trial);
}

void MinimizeTask::finish() {
  qv_instance& s = *s_;
  budget_ -= dampingShare(s, s.dampingStiffness);
  holdToBudget(s, budget_, s.q, s.elasticEnergyAtState, s.end.q, s.end.v, elastic_, s.lastStep);
  // A step held back forfeits the slack: what it removed is not to be won back.
  s.energySlack = s.lastStep.held_back ? 0.0 : std::fmax(0.0, budget_ - stepEnergy(s, s.end.q, s.end.v, elastic_));
  s.elasticEnergyAtState = elastic_;
  // The next step damps with K at this end: the last evaluation's (at_'s), unless the budget moved x.
  const bool definite = at_.definite && !s.lastStep.held_back;
  s.work.presetDefinitesTaken += definite;
  dampAt(s, s.end.q, !s.lastStep.held_back, s.dampingStiffness, definite);
  phase_ = Phase::Done;
}

qv_step_status minimizeStep(qv_instance& s, const StepPredictor& p) {
  MinimizeTask task;
  task.begin(s, p);
  while (task.pending()) task.resume();
  return task.status();
}

} // namespace quiver::rt
