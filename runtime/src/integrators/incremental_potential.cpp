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

// Phi at one iterate, the force scale of its convergence test and the state forces' Jacobian.
struct Point {
  double phi = 0, scale = 0;
  const double* jacobian = nullptr;
};

class Minimizer {
public:
  Minimizer(qv_instance& s, const StepPredictor& p, const double* qt, const double* v0, double* velocity)
      : s_(s), p_(p), qt_(qt), v0_(v0), velocity_(velocity), r_(s.r), m_(*s.model) {}

  // Evaluates Phi at x and leaves its gradient in s.work.gradient, R + S' in s.work.force, K(x) in
  // s.work.stiffness, v(x) in `velocity` and E(x) in `elastic`.
  Point evaluate(const double* x, double* elastic) {
    Point pt;
    double E = 0, S = 0;
    elasticityAt(s_, x, &E, s_.work.force);
    pt.jacobian = s_.loads.addStateForces(x, s_.work.force, &S);
    double inertia = 0, external = 0, damping = 0, inertiaNorm = 0, forceNorm = 0, externalNorm = 0, dampingNorm = 0;
    for (int i = 0; i < r_; ++i) velocity_[i] = v0_[i] + p_.s * (x[i] - qt_[i]);
    for (int i = 0; i < r_; ++i) {
      const double d = x[i] - qt_[i], f = s_.loads.external(i), cv = restDampingForce(s_, i, velocity_);
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

  // Newton direction into s.work.correction: (H + mu I) d = -g, mu the smallest of 0 and a growing
  // ladder that makes the Cholesky factorisation succeed. Returns whether a shift was needed.
  bool direction(const double* jacobian, bool& failed) {
    const double diagonal = p_.w + p_.s * s_.config.rayleigh_alpha;
    double largest = 0;
    for (int i = 0; i < r_; ++i)
      largest = std::fmax(largest, std::fabs(s_.work.stiffness[i * r_ + i]) + std::fabs(jacobian[i * r_ + i]));
    double mu = 0;
    for (int attempt = 0; attempt < 40; ++attempt) {
      for (int i = 0; i < r_; ++i) {
        for (int j = i; j < r_; ++j)  // the upper triangle: all Cholesky reads
          s_.work.system[i * r_ + j] = s_.work.stiffness[i * r_ + j] + jacobian[i * r_ + j] +
                                       p_.s * s_.config.rayleigh_beta * m_.restStiffness[i * r_ + j];
        s_.work.system[i * r_ + i] += diagonal + mu;
        s_.work.correction[i] = -s_.work.gradient[i];
      }
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
  const qv_model& m_;
};

// H = |v|^2/2 + E + S - f^T q at this step's loads (v null: the potential alone).
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

// The budget holds: never end a step with more. Where the position alone holds more, draw it back
// toward the start, whose potential is within the budget; the velocity then gets what is left.
void holdToBudget(qv_instance& s, double budget, double* x, double* velocity, double& elastic, qv_step_report& report) {
  const int r = s.r;
  if (stepEnergy(s, x, nullptr, elastic) > budget) {
    // Bisection on x(t) = q + t (x - q) for the farthest t whose potential is within the budget
    // (t = 0, the start, is); 12 halvings leave t within 1/4096 of it.
    double* farEnd = s.work.segmentEnd;
    std::memcpy(farEnd, x, sizeof(double) * r);
    double within = 0, beyond = 1, withinElastic = s.elasticEnergyAtState;
    for (int cut = 0; cut < 12; ++cut) {
      const double t = 0.5 * (within + beyond);
      for (int i = 0; i < r; ++i) x[i] = s.q[i] + t * (farEnd[i] - s.q[i]);
      const double e = elasticEnergy(*s.model, s.config.elasticity, x, s.work.polynomialScratch);
      if (stepEnergy(s, x, nullptr, e) <= budget) {
        within = t;
        withinElastic = e;
      } else {
        beyond = t;
      }
    }
    for (int i = 0; i < r; ++i) x[i] = s.q[i] + within * (farEnd[i] - s.q[i]);
    elastic = withinElastic;
    report.held_back = 1;
  }
  const double energyAfter = stepEnergy(s, x, velocity, elastic);
  if (energyAfter > budget) {
    const double kinetic = 0.5 * dot(velocity, velocity, r), potential = energyAfter - kinetic;
    const double keep = potential < budget && kinetic > 0 ? std::sqrt((budget - potential) / kinetic) : 0.0;
    for (int i = 0; i < r; ++i) velocity[i] *= keep;
    report.energy_removed = kinetic * (1 - keep * keep);
  }
}

} // namespace

double restDampingForce(const qv_instance& s, int i, const double* v) {
  double c = s.config.rayleigh_alpha * v[i];
  for (int j = 0; j < s.r; ++j) c += s.config.rayleigh_beta * s.model->restStiffness[i * s.r + j] * v[j];
  return c;
}

qv_step_status minimizeStep(qv_instance& s, const StepPredictor& p) {
  const int r = s.r;
  // What the step may end with: what it began with, what earlier steps' discretisation lost and
  // may win back (the trapezoidal rule trades a little energy back and forth on nonlinear models),
  // less what damping dissipates in it (below).
  // Loads that changed since the last step start the budget anew: what the discretisation lost
  // under the old loads is not owed under the new ones.
  if (s.loads.changedSinceLastStep()) s.energySlack = 0;
  double budget = stepEnergy(s, s.q, s.v, s.elasticEnergyAtState) + s.energySlack;
  const double* qt = s.work.predictor;
  const double* v0 = s.work.predictorVelocity;
  double* x = s.end.q;
  double* velocity = s.end.v;
  Minimizer minimizer(s, p, qt, v0, velocity);
  double elastic = 0;
  Point at = minimizer.evaluate(x, &elastic);
  qv_step_status status = QV_STEP_OK;
  qv_step_report& report = s.lastStep;
  for (int it = 0;; ++it) {
    const double gradient = norm(s.work.gradient, r);
    if (!std::isfinite(gradient) || !std::isfinite(at.phi)) return QV_STEP_RESET;  // non-finite input
    report.gradient = gradient / (at.scale + 1e-300);
    if (gradient <= s.config.newton_tolerance * at.scale) {
      report.converged = 1;
      break;
    }
    if (it == s.config.newton_iterations) break;
    bool failed = false;
    if (minimizer.direction(at.jacobian, failed)) status = QV_STEP_INDEFINITE;
    if (failed) break;
    ++report.newton_iterations;
    const double slope = dot(s.work.gradient, s.work.correction, r);  // < 0: a descent direction
    // Backtracking: the first step length that lowers Phi enough (Armijo), or, near the minimum
    // where Phi's change drowns in its rounding, one that keeps Phi within rounding and lowers the
    // gradient. None, and x stays.
    const double roundoff = 1e-12 * std::fabs(at.phi);
    double length = 1;
    bool accepted = false;
    double trialElastic = 0;
    Point trial;
    for (int cut = 0; cut < 30 && !accepted; ++cut, length *= 0.5) {
      for (int i = 0; i < r; ++i) s.work.trial[i] = x[i] + length * s.work.correction[i];
      trial = minimizer.evaluate(s.work.trial, &trialElastic);
      accepted = trial.phi <= at.phi + 1e-4 * length * slope ||
                 (trial.phi <= at.phi + roundoff && norm(s.work.gradient, r) < gradient);
      if (!accepted) ++report.line_search_cuts;
    }
    if (!accepted) {
      at = minimizer.evaluate(x, &elastic);  // back to the last iterate's forces and velocity
      break;
    }
    std::memcpy(x, s.work.trial, sizeof(double) * r);
    at = trial;
    elastic = trialElastic;
  }
  // Damping's share: h v_mid^T C0 v_mid, exact for the trapezoidal rule's linear damping.
  double* mid = s.work.midpointVelocity;
  for (int i = 0; i < r; ++i) mid[i] = 0.5 * (s.v[i] + velocity[i]);
  for (int i = 0; i < r; ++i) budget -= p.h * mid[i] * restDampingForce(s, i, mid);
  holdToBudget(s, budget, x, velocity, elastic, report);
  // A step held back forfeits the slack: what it removed is not to be won back.
  s.energySlack = report.held_back ? 0.0 : std::fmax(0.0, budget - stepEnergy(s, x, velocity, elastic));
  s.elasticEnergyAtState = elastic;
  return status;
}

} // namespace quiver::rt
