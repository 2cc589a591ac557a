// The instance's lifecycle and state: configuration, layout, rest, health, state and energies.
#include "instance.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <new>

#include "c_enum.h"
#include "contact.h"
#include "dense_solve.h"
#include "dynamics.h"
#include "elasticity.h"
#include "formats/model/qvr.h"
#include "integrators/integrator.h"

namespace quiver::rt {

static_assert(QV_MIN_TIME_STEP == quiver::kSmallestTimeStep, "a model's suggested step is one an instance takes");

bool validConfig(const qv_model* model, const qv_instance_config* c) {
  if (!model || !c) return false;
  const int integrator = cEnumValue(c->integrator), solver = cEnumValue(c->solver), elasticity = cEnumValue(c->elasticity);
  return integrator >= 0 && integrator < QV_INTEGRATOR_COUNT && solver >= 0 && solver < QV_SOLVER_COUNT &&
         c->newton_tolerance > 0 && std::isfinite(c->newton_tolerance) && elasticity >= 0 &&
         elasticity < QV_ELASTICITY_COUNT && (!kElasticities[elasticity].needsRotations || model->rotations) &&
         c->time_step >= QV_MIN_TIME_STEP && std::isfinite(c->time_step) && c->newton_iterations >= 1 && c->rayleigh_alpha >= 0 &&
         c->rayleigh_beta >= 0 && c->max_constraints >= 0 && c->max_constraints <= 64 && c->max_displacement > 0 &&
         (c->free_flight == 0 || (c->free_flight == 1 && model->rigidBody)) && c->max_contacts >= 0 &&
         c->max_contacts <= 4096 && (c->soft_contacts == 0 || (c->soft_contacts == 1 && c->free_flight == 1 &&
                                                                integrator != QV_INTEGRATOR_CENTRAL_DIFFERENCES &&
                                                                elasticity != QV_ELASTICITY_MODAL_WARPING)) &&
         c->max_substeps >= 1 && c->max_substeps <= 64;
}

void defaultConfig(qv_instance_config& config, const qv_model* model) {
  config.integrator = QV_INTEGRATOR_IMPLICIT_NEWMARK;
  config.time_step = model ? model->info.time_step : 1.0 / 60.0;
  config.solver = QV_SOLVER_MINIMIZE;
  config.newton_iterations = quiver::rt::kMinimizerIterations;
  config.newton_tolerance = 1e-6;
  config.rayleigh_alpha = model ? model->info.rayleigh_alpha : 0.0;
  config.rayleigh_beta = model ? model->info.rayleigh_beta : 0.0;
  config.max_constraints = 4;
  double diagonal = 1.0;
  if (model) {
    double d2 = 0;
    for (int k = 0; k < 3; ++k) d2 += (model->info.bbox_max[k] - model->info.bbox_min[k]) * (model->info.bbox_max[k] - model->info.bbox_min[k]);
    diagonal = std::sqrt(d2);
  }
  config.max_displacement = 100.0 * diagonal;
  config.elasticity = QV_ELASTICITY_STVK;
  config.free_flight = 0;
  config.max_contacts = 64;
  config.soft_contacts = 0;
  config.max_substeps = 16;
}

size_t instanceBytes(const qv_model& model, const qv_instance_config& config) {
  BlockCarver c(nullptr);
  c.take<qv_instance>(1);
  qv_instance probe{};
  probe.model = &model;
  probe.r = model.info.r;
  probe.config = config;
  probe.carve(c);
  return c.size();
}

qv_instance* constructInstance(const qv_model& model, const qv_instance_config& config, char* block) {
  BlockCarver c(block);
  qv_instance* s = new (c.take<qv_instance>(1)) qv_instance{};
  s->model = &model;
  s->config = config;
  s->r = model.info.r;
  s->carve(c);
  // ||u||_inf <= max_i ||U_i||_1 ||q||_inf: bound q so that no vertex can exceed max_displacement.
  double rowNorm = 0;
  for (size_t row = 0; row < 3 * static_cast<size_t>(model.info.vertex_count); ++row) {
    double sum = 0;
    for (int j = 0; j < s->r; ++j) sum += std::fabs(model.basisEntry(row, static_cast<size_t>(j)));
    rowNorm = std::fmax(rowNorm, sum);
  }
  s->maxQ = rowNorm > 0 ? config.max_displacement / rowNorm : config.max_displacement;
  s->loads.clear();
  if (s->flying()) {
    std::memcpy(s->frame.homePosition, model.rigidBody, sizeof s->frame.homePosition);  // as baked
    s->loads.frame = &s->frame;
    s->loads.model = &model;
    // The surface's vertices touch the world (contact_points.h).
    s->surfaceVertices = model.contactVertices;
    s->surfaceLevels = model.contactLevels;
    s->surfaceCount = model.contactCount;
    for (int k = 0; k < s->surfaceCount; ++k) {
      double r2 = 0;
      for (int a = 0; a < 3; ++a) {
        const double x = model.rest[3 * s->surfaceVertices[k] + a] - model.rigidBody[a];
        r2 += x * x;
        s->surfaceLow[a] = k ? std::fmin(s->surfaceLow[a], x) : x;
        s->surfaceHigh[a] = k ? std::fmax(s->surfaceHigh[a], x) : x;
      }
      s->surfaceRadius = std::fmax(s->surfaceRadius, std::sqrt(r2));
    }
    double d2 = 0;
    for (int a = 0; a < 3; ++a) d2 += std::pow(model.info.bbox_max[a] - model.info.bbox_min[a], 2);
    s->contactSlop = 1e-3 * std::sqrt(d2);
    if (s->modeCompliance) {
      // An implicit step's end x moves by (w I + K + s C)^-1 f under a force f (K and C's stiffness
      // D taken as K(0) here); an impulse P over the step is f = P / h, and x / h is the velocity.
      const double h = config.time_step;
      const StepPredictor p = implicitPredictor(config);
      for (int i = 0; i < s->r; ++i)
        s->modeCompliance[i] = 1 / (h * h * (p.w + p.s * config.rayleigh_alpha +
                                              (1 + p.s * config.rayleigh_beta) * model.contactModes.stiffness[i]));
    }
  }
  s->rest();
  return s;
}

} // namespace quiver::rt

// The vectors every step touches first, together (a crowd's members' blocks are cold at each
// step: contiguous, the prefetcher streams them), then the matrices.
void qv_instance::carve(quiver::rt::BlockCarver& c) {
  const size_t rr = static_cast<size_t>(r) * r;
  q = c.take<double>(r);
  v = c.take<double>(r);
  a = c.take<double>(r);
  previousQ = c.take<double>(r);
  end.q = c.take<double>(r);
  end.v = c.take<double>(r);
  end.a = c.take<double>(r);
  work.force = c.take<double>(r);
  work.correction = c.take<double>(r);
  work.damping = c.take<double>(r);
  work.predictor = c.take<double>(r);
  work.predictorVelocity = c.take<double>(r);
  work.gradient = c.take<double>(r);
  work.trial = c.take<double>(r);
  work.segmentEnd = c.take<double>(r);
  work.midpointVelocity = c.take<double>(r);
  work.stateForceSink = c.take<double>(r);
  work.presetAt = c.take<double>(r);
  work.presetForce = c.take<double>(r);
  loads.carve(c, r, config.max_constraints, flying());
  dampingStiffness = c.take<double>(rr);
  work.stiffness = c.take<double>(rr);
  work.system = c.take<double>(rr);
  work.polynomialScratch = c.take<double>(quiver::rt::ReducedPolynomial::scratchSize(r));
  if (flying()) {
    frame.attach(c.take<double>(quiver::rt::RigidFrame::scratchDoubles(r)), r);
    startQ = c.take<double>(r);
    if (config.soft_contacts && model->contactModes.stiffness) {
      modeCompliance = c.take<double>(r);
      modeVelocity = c.take<double>(r);
      deformedSurface = c.take<double>(3 * static_cast<size_t>(model->contactCount));
    }
    contacts.contacts = c.take<quiver::rt::Contact>(static_cast<size_t>(config.max_contacts));
    contacts.previous = c.take<quiver::rt::Contact>(static_cast<size_t>(config.max_contacts));
    contacts.turns = c.take<quiver::rt::ContactTurns>(static_cast<size_t>(config.max_contacts));
    contacts.order = c.take<int>(static_cast<size_t>(config.max_contacts));
    contacts.pairs = c.take<quiver::rt::ContactPair>(static_cast<size_t>(config.max_contacts));
    contacts.capacity = config.max_contacts;
  }
}

void qv_instance::rest() {
  std::memset(q, 0, sizeof(double) * r);
  std::memset(v, 0, sizeof(double) * r);
  std::memset(a, 0, sizeof(double) * r);
  elasticEnergyAtState = 0;
  energySlack = 0;
  openEnergyAccount(0);
  quiver::rt::dampWithStiffness(*this, model->restStiffness, dampingStiffness);
  contacts.clear();
  if (flying()) frame.goHome();
}

void qv_instance::openEnergyAccount(double elastic) {
  elasticAllowance = elastic + energySlack;
  exactEndChecks = 0;
  std::memcpy(previousQ, q, sizeof(double) * r);
  previousElastic = elastic;
}

bool qv_instance::withinBounds(const double* endQ, const double* endV, const double* endA) const {
  for (int i = 0; i < r; ++i)
    if (!(std::fabs(endQ[i]) <= maxQ) || !std::isfinite(endV[i]) || !std::isfinite(endA[i])) return false;
  return true;
}

bool qv_instance::healthy() const {
  // The implicit integrators' steps cannot run away on finite input (a fixed Newton step that
  // would is taken by the minimiser instead), so only non-finite states reset them.
  if (config.integrator == QV_INTEGRATOR_CENTRAL_DIFFERENCES) {
    if (!withinBounds(q, v, a)) return false;
  } else {
    for (int i = 0; i < r; ++i)
      if (!std::isfinite(q[i]) || !std::isfinite(v[i]) || !std::isfinite(a[i])) return false;
  }
  return !flying() || frame.finite();
}

void qv_instance::addVertexForce(int vertex, const double force[3]) {
  if (!flying()) {
    loads.addVertexForce(*model, config.elasticity, q, vertex, force);
    return;
  }
  // On the frame: the force, and its torque about the centre of mass from where the vertex is.
  double u[3], p[3], world[3], body[3];
  model->vertexLinear(vertex, q, u, nullptr);
  for (int c = 0; c < 3; ++c) p[c] = model->rest[3 * vertex + c] - model->rigidBody[c] + u[c];
  frame.toWorld(p, world);
  const double* x = frame.position;
  const double arm[3] = {world[0] - x[0], world[1] - x[1], world[2] - x[2]};
  frame.torque[0] += arm[1] * force[2] - arm[2] * force[1];
  frame.torque[1] += arm[2] * force[0] - arm[0] * force[2];
  frame.torque[2] += arm[0] * force[1] - arm[1] * force[0];
  for (int c = 0; c < 3; ++c) frame.force[c] += force[c];
  // On q: the force seen from the body.
  frame.toBody(force, body);
  loads.addVertexForce(*model, config.elasticity, q, vertex, body);
}

void qv_instance::setGravity(const double g[3]) {
  if (!flying()) {
    loads.setGravity(*model, g);
    return;
  }
  // A uniform field accelerates the frame and everything in it alike: nothing of it deforms q.
  std::memcpy(frame.gravity, g, sizeof frame.gravity);
  loads.changed = true;
}

void qv_instance::beginStep() {
  lastStep = qv_step_report{};
  softContact = false;
  touching = false;
  if (!flying()) return;
  const double h = config.time_step;
  frame.refresh(*model, q, v);
  frame.holdSpin();
  std::memset(loads.frameForce, 0, sizeof(double) * r);
  // The frame's acceleration beyond gravity, -G R^T F / m, which q feels through G = U^T M e_a
  // (zero for a free bake's basis, which carries no momentum).
  double accel[3], body[3];
  for (int c = 0; c < 3; ++c) accel[c] = -frame.force[c] / model->info.total_mass;
  frame.toBody(accel, body);
  for (int j = 0; j < r; ++j)
    loads.frameForce[j] += model->gravity[j] * body[0] + model->gravity[r + j] * body[1] + model->gravity[2 * r + j] * body[2];
  frame.accelerate(*model, h);
}

void qv_instance::predictContactModes() {
  // The step's end x = q + d solves H d = w p - (R(q) + S(q) - f) - C v0 + s C p (the integrator's
  // equation linearised at q, its predictor qt = q + p and v0), H = w I + K + s C, which is
  // diagonal in the contact modes with K = K(0): d_i / h = c_i h (rhs)_i.
  const double h = config.time_step;
  const bool newmark = config.integrator == QV_INTEGRATOR_IMPLICIT_NEWMARK;
  const quiver::rt::StepPredictor p = quiver::rt::implicitPredictor(config);
  double* resisting = work.trial;  // free until the step
  quiver::rt::evaluateElasticity(*model, config.elasticity, q, nullptr, resisting, nullptr, work.polynomialScratch);
  loads.addStateForces(q, resisting);
  for (int j = 0; j < r; ++j) resisting[j] -= loads.external(j);
  const double* V = model->contactModes.vectors;
  for (int i = 0; i < r; ++i) {
    double vi = 0, ai = 0, fi = 0;
    for (int j = 0; j < r; ++j) vi += V[j * r + i] * v[j], ai += V[j * r + i] * a[j], fi += V[j * r + i] * resisting[j];
    const double C = config.rayleigh_alpha + config.rayleigh_beta * model->contactModes.stiffness[i];
    const double step = newmark ? h * vi + 0.25 * h * h * ai : h * vi;
    const double start = newmark ? vi + 0.5 * h * ai : vi;
    modeVelocity[i] = modeCompliance[i] * h * (p.w * step - fi - C * start + p.s * C * step);
  }
}

void qv_instance::solveOwnContacts() {
  quiver::rt::ContactBody body;
  body.instance = this;
  quiver::rt::takeMomenta(&body, 1, colliders, colliderCount, config.time_step);
  quiver::rt::solveContacts(&body, 1, colliders, colliderCount, quiver::rt::ContactMaterial{}, contacts, config.time_step);
}

qv_step_status qv_instance::finishStep() {
  const int substeps = deformationSubsteps();
  if (substeps == 1) {
    moveFrame();
    return endStep(quiver::rt::kIntegrators[config.integrator].step(*this));
  }
  // Each substep is a step of h / substeps but for the loads, which act on, and the frame's
  // momenta, which took the step's forces, torques and contact impulses at its start.
  const double h = config.time_step;
  config.time_step = h / substeps;
  qv_step_report report{};
  qv_step_status status = QV_STEP_OK;
  for (int k = 0; k < substeps; ++k) {
    if (k > 0) {
      loads.continueStep();
      takeOutTurnExcess(true);
      frame.refresh(*model, q, v);
      frame.holdSpin();
    }
    moveFrame();
    const qv_step_status sub = quiver::rt::kIntegrators[config.integrator].step(*this);
    status = std::max(status, sub);
    report.newton_iterations += lastStep.newton_iterations;
    report.line_search_cuts += lastStep.line_search_cuts;
    report.converged = (k == 0 || report.converged) && lastStep.converged;
    report.gradient = std::fmax(report.gradient, lastStep.gradient);
    report.held_back |= lastStep.held_back;
    report.energy_removed += lastStep.energy_removed;
    report.minimized |= lastStep.minimized;
    report.substeps = k + 1;
    lastStep = qv_step_report{};
    if (sub == QV_STEP_RESET || !healthy()) break;
  }
  config.time_step = h;
  lastStep = report;
  return endStep(status);
}

int qv_instance::deformationSubsteps() const {
  // The step's minimisation turns non-convex where the spin's softening omega^2 outgrows the
  // step's inertia 4 / h^2 and the stretched body's stiffness; past about 1 rad a step a spun body's
  // energy rose (a 10 kPa block: +15% at 1 rad, 2.4- to 3-fold at 1.7-2.3 rad; a bar 7-fold) and
  // 0.75 rad kept it within 1% (docs/architecture.md, Free flight). The rate is the faster of the
  // deformed and the rest shape's, so that a stretched body that springs back, spinning up within
  // the step, is cut as finely.
  constexpr double kTurnPerSubstep = 0.75;
  if (!flying()) return 1;
  const double n = std::ceil(config.time_step * frame.spinRate(*model) / kTurnPerSubstep);
  return n > 1 ? static_cast<int>(std::fmin(n, config.max_substeps)) : 1;  // NaN: 1 (the step resets)
}

void qv_instance::moveFrame() {
  if (flying()) frame.move(config.time_step);
}

qv_step_status qv_instance::endStep(qv_step_status status) {
  lastStep.substeps = std::max(lastStep.substeps, 1);
  work.presetValid = false;
  work.presetFactor = quiver::rt::LaneFactor{};
  // The group's scratch is overwritten after its step, and no step reads K before evaluating it.
  work.stiffnessPacked = nullptr;
  loads.endStep();
  if (flying() && status != QV_STEP_RESET) takeOutTurnExcess(false);
  if (status == QV_STEP_RESET || !healthy()) {
    rest();
    return QV_STEP_RESET;
  }
  return status;
}

void qv_instance::takeOutTurnExcess(bool betweenSubsteps) {
  // Not with contacts in reach or where a torque changed the spin: as loads that changed start the
  // energy budget anew, the spin owes nothing the turns took before, and what the turn adds there
  // is the contacts' to take out (settled there, a pile kept rocking and fell asleep 1-3 s later,
  // and a soft bar on the ground still moved at 1e-4 m/s after 3 s). Contacts in reach, not their
  // impulses: whether an impulse is exactly zero is not a choice rounding should make. Between
  // substeps the contacts have acted (on the frame, at the step's start): settled there whatever is
  // in reach, or a bar spun at 500 rad/s tumbling on the ground gained 5%
  // (FreeFlight.FastSpinsBesideTheGroundNeverGainEnergy).
  if ((!betweenSubsteps && touching) || frame.spinChangedSinceHold()) {
    frame.turnCredit = 0;
    return;
  }
  // A negative credit is a debt: what q' could not give when the turns added more than it held.
  const double owed = frame.turnExcess(*model, q, v) - frame.turnCredit;
  if (!(owed > 0)) {
    if (owed <= 0) frame.turnCredit = -owed;  // NaN: kept (the step resets)
    return;
  }
  double kinetic = 0;
  for (int i = 0; i < r; ++i) kinetic += 0.5 * v[i] * v[i];
  const double keep = kinetic > owed ? std::sqrt((kinetic - owed) / kinetic) : 0.0;
  for (int i = 0; i < r; ++i) v[i] *= keep;
  const double debt = owed - kinetic;  // infinite only from a crafted snapshot's credit
  frame.turnCredit = debt > 0 && std::isfinite(debt) ? -debt : 0.0;
  lastStep.energy_removed += kinetic * (1 - keep * keep);
}

void qv_instance::beginOwnStep() {
  beginStep();
  if (flying()) solveOwnContacts();
}

qv_step_status qv_instance::step() {
  beginOwnStep();
  return finishStep();
}

void qv_instance::setState(const double* newQ, const double* newV, const double* newA) {
  if (newQ && newQ != q) std::memcpy(q, newQ, sizeof(double) * r);
  if (newV && newV != v) std::memcpy(v, newV, sizeof(double) * r);  // (a new rigid state passes v itself)
  const bool consistentA = !newA && (newQ || newV);
  if (flying() && (newQ || newV)) {  // the centrifugal force at the new state's spin
    frame.refresh(*model, q, v);
    frame.holdSpin();
  }
  if (newQ || consistentA) quiver::rt::evaluateForces(*this, q);  // R(q) + S(q), K(q)
  // Fixed Newton steps keep E(q) only in their account, which a new q or velocity opens anew.
  const bool newAccount = keepsEnergyAccount() && (newQ || newV);
  if (newQ || newAccount)
    elasticEnergyAtState = quiver::rt::elasticEnergy(*model, config.elasticity, q, work.polynomialScratch);
  if (newQ) quiver::rt::dampAt(*this, q, true, dampingStiffness);  // K(q) just evaluated
  if (newQ || newV) frame.turnCredit = 0;  // a new state owes and is owed nothing
  if (newA) {
    std::memcpy(a, newA, sizeof(double) * r);
  } else if (consistentA) {
    // The acceleration the equations of motion give at the new state (persistent loads only), so
    // that the next implicit step starts consistent rather than injecting energy; damped as the
    // solver damps.
    if (minimizes())
      quiver::rt::dampingForces(*this, dampingStiffness, v, work.damping);
    else
      quiver::rt::dampingForces(*this, v, work.damping);
    for (int i = 0; i < r; ++i) a[i] = loads.gravityForce[i] - work.force[i] - work.damping[i];
  }
  energySlack = 0;
  if (newAccount) openEnergyAccount(elasticEnergyAtState);
}

void qv_instance::saveState(double* out) const {
  out[0] = r;
  std::memcpy(out + 1, q, sizeof(double) * r);
  std::memcpy(out + 1 + r, v, sizeof(double) * r);
  std::memcpy(out + 1 + 2 * r, a, sizeof(double) * r);
  // The minimiser's energy budget. Fixed Newton steps leave E(q) to their next step: it is
  // evaluated here, and their account written as the slack it leaves (negative: an excess), which a
  // minimising instance restored from it owes too; their own reads the account at the end. Other
  // instances write the account a fixed Newton instance opens at this state.
  const bool budgeted = minimizes(), account = keepsEnergyAccount();
  const double elastic = budgeted ? elasticEnergyAtState : quiver::rt::elasticEnergy(*model, config.elasticity, q, work.polynomialScratch);
  out[1 + 3 * r] = elastic;
  out[2 + 3 * r] = budgeted ? energySlack : account ? elasticAllowance - elastic : 0.0;
  double* f = out + 3 + 3 * r;
  if (flying()) {
    std::memcpy(f, frame.position, 3 * sizeof(double));
    std::memcpy(f + 3, frame.orientation, 4 * sizeof(double));
    std::memcpy(f + 7, frame.velocity, 3 * sizeof(double));
    std::memcpy(f + 10, frame.angularMomentum, 3 * sizeof(double));
    f[13] = frame.turnCredit;
    std::memcpy(f + 14, frame.homePosition, 3 * sizeof(double));
    std::memcpy(f + 17, frame.homeOrientation, 4 * sizeof(double));
    f += 21;
  }
  // D, likewise: the minimiser's, or the one it would start from here. Written, not recomputed on
  // restoring: a group evaluates K(q) in a different order than one instance does, so only the
  // saved bits repeat the same steps.
  const double* D = dampingStiffness;
  if (!budgeted) {
    quiver::rt::dampAt(*this, q, false, work.stiffness);
    D = work.stiffness;
  }
  for (int i = 0; i < r; ++i)
    for (int j = i; j < r; ++j) *f++ = D[i * r + j];
  // What the next step compares its loads with (Loads::changedSinceLastStep()).
  std::memcpy(f, loads.lastStepForce, sizeof(double) * r);
  f[r] = loads.changed ? 1.0 : 0.0;
  f[r + 1] = account ? elasticAllowance : elastic + out[2 + 3 * r];
  f[r + 2] = account ? previousElastic : elastic;
  std::memcpy(f + r + 3, account ? previousQ : q, sizeof(double) * r);
  f[2 * r + 3] = account ? exactEndChecks : 0;
}

bool qv_instance::validState(const double* in) const {
  if (in[0] != r) return false;
  // A state, a budget, a frame or an account that is not finite would only be reset by the next
  // step. The last step's forces may hold one (a step that reset): it only marks a change.
  const size_t lastForces = 3 + 3 * static_cast<size_t>(r) + frameSnapshotSize() + static_cast<size_t>(r) * (r + 1) / 2;
  for (size_t i = 1; i < stateSize(); ++i)
    if ((i < lastForces || i >= lastForces + r) && !std::isfinite(in[i])) return false;
  if (flying()) {  // orientations (the frame's, the home pose's) of length 0 or beyond range (crafted) turn nothing
    for (const size_t at : {size_t{3}, size_t{17}}) {
      const double* o = in + 3 + 3 * r + at;
      const double length2 = o[0] * o[0] + o[1] * o[1] + o[2] * o[2] + o[3] * o[3];
      if (!(length2 > 0 && length2 < INFINITY)) return false;
    }
  }
  // D must be positive definite, or the damping would add energy.
  const double* savedD = in + 3 + 3 * r + frameSnapshotSize();
  for (int i = 0, k = 0; i < r; ++i)
    for (int j = i; j < r; ++j) work.system[i * r + j] = savedD[k++];
  return quiver::rt::choleskyFactor(work.system, r);
}

void qv_instance::restoreState(const double* in) {
  const double* savedD = in + 3 + 3 * r + frameSnapshotSize();
  for (int i = 0, k = 0; i < r; ++i)
    for (int j = i; j < r; ++j, ++k) dampingStiffness[i * r + j] = dampingStiffness[j * r + i] = savedD[k];
  const double* savedLoads = savedD + static_cast<size_t>(r) * (r + 1) / 2;
  std::memcpy(loads.lastStepForce, savedLoads, sizeof(double) * r);
  loads.changed = savedLoads[r] != 0;
  std::memcpy(q, in + 1, sizeof(double) * r);
  std::memcpy(v, in + 1 + r, sizeof(double) * r);
  std::memcpy(a, in + 1 + 2 * r, sizeof(double) * r);
  elasticEnergyAtState = in[1 + 3 * r];
  energySlack = in[2 + 3 * r];
  elasticAllowance = savedLoads[r + 1];
  previousElastic = savedLoads[r + 2];
  std::memcpy(previousQ, savedLoads + r + 3, sizeof(double) * r);
  exactEndChecks = static_cast<int>(std::fmin(std::fmax(savedLoads[2 * r + 3], 0.0), 1e6));
  if (flying()) {
    const double* f = in + 3 + 3 * r;
    std::memcpy(frame.position, f, 3 * sizeof(double));
    // As saved, so that the steps repeat bit for bit; one not of unit length (crafted) normalised.
    const double* o = f + 3;
    if (std::fabs(o[0] * o[0] + o[1] * o[1] + o[2] * o[2] + o[3] * o[3] - 1) <= 1e-12)
      frame.takeOrientation(o);
    else
      frame.setOrientation(o);
    std::memcpy(frame.velocity, f + 7, 3 * sizeof(double));
    std::memcpy(frame.angularMomentum, f + 10, 3 * sizeof(double));
    frame.turnCredit = f[13];  // finite, as checked above; negative: a debt
    // The pose a reset goes to (goHome() normalises its orientation).
    std::memcpy(frame.homePosition, f + 14, 3 * sizeof(double));
    std::memcpy(frame.homeOrientation, f + 17, 4 * sizeof(double));
    // What the frame derives from the state, which a step refreshes at its start but a world's
    // sleepers are read with unstepped (their spin and inertia decide who can touch them).
    frame.refresh(*model, q, v);
  }
}

size_t qv_instance::saveSnapshot(double* out) const {
  saveState(out);
  return sizeof(double) * (stateSize() + (flying() ? quiver::rt::saveContacts(contacts, out + stateSize()) : 0));
}

bool qv_instance::restoreSnapshot(const double* in, size_t bytes) {
  const size_t available = bytes / sizeof(double);
  if (bytes > snapshotSize() || available < stateSize() || !validState(in)) return false;
  const qv_instance* self = this;
  if (flying() && !quiver::rt::validContacts(in + stateSize(), available - stateSize(), contacts, &self, 1, colliderCount))
    return false;
  restoreState(in);
  // Its contacts, which the next step warm-starts from; a world's members keep theirs in the world.
  if (flying()) quiver::rt::restoreContacts(contacts, in + stateSize());
  return true;
}

void qv_instance::energies(double* kinetic, double* elastic) const {
  if (kinetic) {
    double k = 0;
    for (int i = 0; i < r; ++i) k += 0.5 * v[i] * v[i];
    if (flying()) {
      quiver::rt::RigidFrame f = frame;  // refreshed on the side: energies() changes no state
      f.refresh(*model, q, v);
      k += f.kineticEnergy(*model);
    }
    *kinetic = k;
  }
  if (elastic) *elastic = quiver::rt::elasticEnergy(*model, config.elasticity, q, work.polynomialScratch);
}
