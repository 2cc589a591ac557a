#pragma once
// qv_instance: one simulated object, in one block: its settings, its state (q, v, a), its loads
// and the buffers of the step. Integrators (integrators/) advance it; dynamics.h evaluates it.
#include "block_carver.h"
#include "cholesky_lanes.h"
#include "contact_list.h"
#include "loads.h"
#include "model.h"
#include "rigid_frame.h"

namespace quiver::rt {

// The integrator's estimate of the state at the end of the step: each implicit integrator iterates
// on one of them and derives the others; the explicit one computes them in turn.
struct EndOfStep {
  double* q = nullptr;
  double* v = nullptr;
  double* a = nullptr;
};

// The symmetric matrices both solvers factorise (dynamics.h): stiffness K(q) + stateJacobian J +
// dampingStiffness D (qv_instance) + identity I, each term scaled.
struct SystemScales {
  double stiffness = 0, stateJacobian = 0, dampingStiffness = 0, identity = 0;
  bool operator==(const SystemScales& o) const {
    return stiffness == o.stiffness && stateJacobian == o.stateJacobian && dampingStiffness == o.dampingStiffness &&
           identity == o.identity;
  }
};

// What one evaluation at a trial state fills, and the Newton system built from it.
struct StepBuffers {
  double* force = nullptr;        // R(q) plus the state forces (resisting: the step subtracts it)
  double* stiffness = nullptr;    // K(q), elastic only (Rayleigh damping uses it), unless in stiffnessPacked
  // K(q) where a group evaluated it: its upper triangle packed row by row in the group's scratch
  // (step_many.h), not copied here until a reader needs the whole matrix (wholeStiffness(),
  // dynamics.h). The damping products read it there: the whole matrix written into every member
  // had cost more than both products of a fixed Newton step.
  // Mutable: a snapshot, a const query, evaluates K into `stiffness` too (dampAt(), dynamics.h).
  mutable const double* stiffnessPacked = nullptr;
  double* system = nullptr;       // the Newton matrix, factorised in place
  double* correction = nullptr;   // the Newton right-hand side in, the correction out
  double* damping = nullptr;      // C v (dampingForces(), dynamics.h)
  double* predictor = nullptr;    // the minimising solver's qt and v0 (incremental_potential.h)
  double* predictorVelocity = nullptr;
  double* gradient = nullptr;     // its gradient at the current iterate
  double* trial = nullptr;        // its line search's trial point
  double* segmentEnd = nullptr;   // the far end of the segment the energy budget bisects
  double* midpointVelocity = nullptr;  // (v_start + v_end) / 2, for damping's share of the budget
  double* stateForceSink = nullptr;    // where stepEnergy() lets the state forces add the force it does not need
  double* polynomialScratch = nullptr;
  // A group stepped together (step_many.h) evaluates each member's polynomial at the point its
  // step will evaluate next: R(q) and E(q) here, K(q) in the group's scratch. The step's next elastic
  // evaluation takes them when it is at exactly that point (elasticityAt(), dynamics.h).
  double* presetAt = nullptr;
  double* presetForce = nullptr;
  const double* presetStiffness = nullptr;  // packed, as stiffnessPacked
  double presetEnergy = 0;
  bool presetValid = false;
  // Whether the group found that K(q) positive definite, as choleskyFactor() judges (a minimising
  // step's damping at its end takes it as it is: dampWithStiffness()).
  bool presetDefinite = false;
  unsigned long long presetDefinitesTaken = 0;  // ends damped by that verdict (tests, diagnostics)
  // The group also factorises the matrix the step will solve with at that point (the system with
  // presetScales), in its own scratch; the solver takes it right after the preset
  // (takePresetFactor(), dynamics.h) instead of filling and factorising its own. Untaken (the
  // step ended, or went elsewhere), it is dropped when the step evaluates elsewhere or ends, and
  // replaced at the group's next evaluation, before the scratch is overwritten.
  LaneFactor presetFactor;
  SystemScales presetScales;
  unsigned long long presetFactorsTaken = 0;  // solves that took a group's factor (tests, diagnostics)
};

// Bytes of the block an instance with `config` needs (64-byte aligned).
size_t instanceBytes(const qv_model& model, const qv_instance_config& config);
bool validConfig(const qv_model* model, const qv_instance_config* config);
// Builds the instance at rest, with no loads, in `block` (instanceBytes() bytes).
qv_instance* constructInstance(const qv_model& model, const qv_instance_config& config, char* block);
void defaultConfig(qv_instance_config& config, const qv_model* model);

} // namespace quiver::rt

struct qv_instance {
  const qv_model* model;
  qv_allocator allocator;
  bool ownsMemory;
  qv_instance_config config;
  int r;
  double maxQ;  // |q|_inf past which a step has blown up (a fixed Newton step's end, central differences)
  double *q, *v, *a;
  double elasticEnergyAtState;  // E(q) for the energy budget (a fixed Newton step's end leaves it stale)
  double energySlack;           // energy the discretisation lost that a later step may win back
  // QV_SOLVER_NEWTON's energy account (integrators/fixed_newton.h), which the next fixed step's start
  // settles: the most E(q) the state may hold within the last step's budget, and where that step
  // started (q and E(q)), toward which the state is drawn back where its position alone holds more.
  // Opened at the state itself (openEnergyAccount()) where no fixed step left it.
  double elasticAllowance;
  double* previousQ;
  double previousElastic;
  int exactEndChecks;  // steps left whose ends are held to the budget at once (fixed_newton.h)
  // D, r x r: the minimising solver's Rayleigh damping C = alpha I + beta D through a step. K(q) at
  // the step's start, shifted to positive definite where compression made it indefinite
  // (dampWithStiffness(), dynamics.h).
  double* dampingStiffness;
  qv_step_report lastStep;
  quiver::rt::Loads loads;
  quiver::rt::EndOfStep end;
  quiver::rt::StepBuffers work;
  quiver::rt::RigidFrame frame;  // in flight (config.free_flight) only
  const qv_collider* colliders = nullptr;  // the caller's (qv_instance_set_colliders)
  int colliderCount = 0;
  quiver::rt::ContactList contacts;  // the last step's and the one before, config.max_contacts each (contact.h)
  const int* surfaceVertices = nullptr;  // in flight: the contact points, the model's (contact_points.h)
  const unsigned char* surfaceLevels = nullptr;
  int surfaceCount = 0;
  double surfaceRadius = 0;        // m: the farthest surface vertex from the centre of mass, at rest
  // m: the box of the contact points in body axes, from the centre of mass: at rest, or with soft
  // contacts as deformed at the last contact search (deformedSurface, 3 doubles each point, then).
  double surfaceLow[3] = {}, surfaceHigh[3] = {};
  double* deformedSurface = nullptr;
  double contactSlop = 0;          // m: penetration left alone
  // In a world (world.h): asleep, not stepped until woken; still for stillTime s (slower than its
  // sleep speed); sleepGroup: the group it fell asleep with (-1: none), which it wakes with.
  // Whatever the caller changes wakes it (api.cpp).
  bool asleep = false;
  double stillTime = 0;
  int sleepGroup = -1;
  double* startQ = nullptr;  // in flight: q at a world step's start, to measure how far it moved q
  // With soft contacts (config.soft_contacts): how far the step moves each of the model's contact modes
  // (contact_modes.h) per unit impulse along it, over h (a velocity), 1 / (h^2 (w + s alpha +
  // (1 + s beta) lambda)) with the integrator's w and s (incremental_potential.h); null otherwise.
  // modeVelocity: the modes' velocity over the step in a contact solve, from predictContactModes()
  // and the impulses since.
  double* modeCompliance = nullptr;
  double* modeVelocity = nullptr;
  // This step's contact solve let its deformation give way (soft contacts touching it, or within reach).
  bool softContact = false;
  // This step's contact solve held a contact of its own or against its surface (alone or in a world,
  // whose contacts are the world's).
  bool touching = false;

  void carve(quiver::rt::BlockCarver& c);
  // The fixed Newton account at this state, E(q) = `elastic`, with the energy slack kept.
  void openEnergyAccount(double elastic);
  void rest();
  bool healthy() const;
  // A step's end (q, v, a): finite, and |q| within maxQ.
  bool withinBounds(const double* q, const double* v, const double* a) const;
  // One step of the configured integrator; per-step loads are spent; a blown-up state resets.
  qv_step_status step();
  void setState(const double* q, const double* v, const double* a);
  bool flying() const { return config.free_flight != 0; }
  // How fast the step would move the contact modes under its loads so far, contact forces not yet
  // among them (modeCompliance not null): the implicit step linearised at q, into modeVelocity.
  void predictContactModes();
  void wake() { asleep = false, stillTime = 0; }
  // Its steps are the minimiser's, which keeps E(q), the energy slack and D from step to step.
  bool minimizes() const {
    return config.solver == QV_SOLVER_MINIMIZE && config.integrator != QV_INTEGRATOR_CENTRAL_DIFFERENCES;
  }
  // Its steps are fixed Newton steps, which keep the energy account (integrators/fixed_newton.h).
  bool keepsEnergyAccount() const {
    return config.solver == QV_SOLVER_NEWTON && config.integrator != QV_INTEGRATOR_CENTRAL_DIFFERENCES;
  }
  // A world force on a vertex: on q (and, in flight, on the frame).
  void addVertexForce(int vertex, const double force[3]);
  void setGravity(const double acceleration[3]);
  // A step in three parts, so that a world can solve its instances' contacts between the first and
  // the last: the frame's forces on q and its momenta (in flight), its contacts, its move and q's step.
  void beginStep();
  void solveOwnContacts();
  void beginOwnStep();  // beginStep() and, in flight, solveOwnContacts(): a step outside a world, up to finishStep()
  qv_step_status finishStep();  // moveFrame() and the integrator's step, in substeps spinning fast; endStep()
  void moveFrame();              // in flight, the frame's move over the step, before q's
  // In flight, the substeps finishStep() cuts the step into, so that the body turns at most 0.75 rad
  // in each (max_substeps); after beginStep() and the contacts. A group steps such members alone.
  int deformationSubsteps() const;
  qv_step_status endStep(qv_step_status status);  // the per-step loads are spent; a blown-up state resets
  // In flight, after q's step: what the frame's turn added to the centrifugal potential
  // (RigidFrame::turnExcess()) beyond what earlier turns took (RigidFrame::turnCredit) is taken out
  // of q'; what q' does not hold is owed (a negative credit) by the next steps. After a step, or
  // between its substeps (which settle with contacts in reach too).
  void takeOutTurnExcess(bool betweenSubsteps);
  // The snapshot: its state, then in flight the last step's contacts (contact_list.h). The state:
  // r, then q, v, a, E(q) and the energy slack, then in flight the frame (position, orientation,
  // velocity, angular momentum, turn credit, and the home pose: position, orientation), then D's upper triangle row by row, then the last
  // step's per-step forces and whether a persistent load changed since (1 or 0), then the fixed
  // Newton account (the elastic allowance, the previous E(q) and q, the exact end checks left), as
  // doubles: all a step reads beyond the caller's calls. A world's snapshot (world.h) holds its
  // members' states and its own contacts.
  size_t stateSize() const {
    const size_t n = static_cast<size_t>(r);
    return 3 * n + 3 + frameSnapshotSize() + n * (n + 1) / 2 + 2 * n + 4;
  }
  size_t frameSnapshotSize() const { return flying() ? 21 : 0; }
  void saveState(double* out) const;
  bool validState(const double* in) const;  // checks D in the scratch: one thread at a time
  void restoreState(const double* in);      // validState() first
  // Bytes: the most a snapshot takes (every contact held), and what this one took.
  size_t snapshotSize() const {
    return sizeof(double) * (stateSize() + (flying() ? 1 + quiver::rt::kContactRecord * static_cast<size_t>(contacts.capacity) : 0));
  }
  size_t saveSnapshot(double* out) const;
  bool restoreSnapshot(const double* in, size_t bytes);
  void energies(double* kinetic, double* elastic) const;
};
