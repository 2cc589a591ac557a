#pragma once
// The world's forces on one instance, in reduced coordinates (f = U^T f_world):
// - per-step forces (on a vertex, or already reduced), cleared by every step;
// - gravity G g, persistent;
// - penalty constraints in slots, k/2 |X_v + U_v q - target_v|^2 per vertex, persistent: the
//   mouse spring, or a group held at targets the caller moves (drag and twist).
//
// State-dependent forces. The implicit step needs, at every trial q, the forces that depend on
// the state and their Jacobian; addStateForces() is the one place they come from. It adds their
// resisting force (the sign of R(q): the step subtracts it) to `force` and returns the Jacobian of
// what it added, which the Newton system adds to the elastic stiffness (Rayleigh damping stays
// elastic only). Penalty constraints are linear in q, so their Jacobian is the constant sum of
// the active slots and is returned as it is. A term whose Jacobian depends on q (contact) writes
// that sum plus its own into a buffer it owns and returns the buffer; a term that also depends on
// the velocity (contact damping, friction) adds its velocity Jacobian to the c1 part of the system.
// In flight the frame's centrifugal potential (rigid_frame.h) is such a term.
#include "block_carver.h"
#include "model.h"
#include "rigid_frame.h"

namespace quiver::rt {

struct Loads {
  int r = 0;
  int slots = 0;
  double* stepForce = nullptr;     // this step's only
  double* gravityForce = nullptr;  // G g
  double* frameForce = nullptr;    // in flight, the moving frame's forces on q this step (zero otherwise): they
                                   // follow the motion, so they are no change of load (changedSinceLastStep)
  double* constraintK = nullptr;   // sum over active slots of k U_v^T U_v
  double* constraintB = nullptr;   // sum over active slots of k U_v^T (target - X_v)
  double* slotK = nullptr;         // per slot
  double* slotB = nullptr;
  int* slotActive = nullptr;
  bool constrained = false;        // some slot is active (else the constraint sums are zero)
  double* lastStepForce = nullptr; // the per-step forces of the step before
  bool changed = false;            // a persistent load was set since the last step
  const RigidFrame* frame = nullptr;  // in flight: its centrifugal potential is a state force
  const qv_model* model = nullptr;    // with it, the model the frame carries
  double* stateJacobian = nullptr;    // in flight: the constraints' Jacobian plus the centrifugal one

  // Takes the arrays from `c` (null pointers while it measures).
  void carve(BlockCarver& c, int reducedSize, int slotCount, bool flying);
  void clear();  // nothing acting

  double external(int i) const { return stepForce[i] + gravityForce[i] + frameForce[i]; }
  // `energy`, when not null, receives the state forces' potential at q (the minimising solver needs
  // it: every state force it steps with must have one, up to a constant).
  const double* addStateForces(const double* q, double* force, double* energy = nullptr) const;
  void endStep();  // the per-step forces are spent, and the persistent ones are the last step's
  // Between a step's substeps: the next substep's loads are this one's, no change of load.
  void continueStep();
  // Whether this step's loads differ from the last step's (a per-step force applied again unchanged
  // is no change): the same answer however often a step asks (a fixed Newton step and the minimiser
  // that takes it over both do).
  bool changedSinceLastStep() const;

  // `q`: the current state, to rotate the force into the vertex's frame under modal warping.
  void addVertexForce(const qv_model& model, qv_elasticity elasticity, const double* q, int vertex,
                      const double force[3]);
  void addReducedForce(const double* force);
  void setGravity(const qv_model& model, const double acceleration[3]);
  void setConstraint(const qv_model& model, int slot, const int* vertices, int count, const double* targets,
                     double stiffness);
  void clearConstraint(int slot);

private:
  void combineConstraints();
};

} // namespace quiver::rt
