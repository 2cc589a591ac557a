#pragma once
// Free flight: a free object's moving frame (the floating frame of reference of reduced
// deformables). The state is the frame, its centre of mass x, orientation R, velocity v and
// angular momentum L in the world, and the deformation q, q' in the frame; a vertex is at
//   x + R p,  p = X - c + U q  (body frame; c the rest centre of mass).
// A free bake's basis is M-orthogonal to the rigid motions, so the centre of mass stays at the
// frame's origin and U q carries no momentum of its own to first order.
//
// What each step keeps, and how (docs/architecture.md, "Free flight"):
// - Linear and angular momentum are the state: P = m v and L change only by the external force
//   and torque (symplectic Euler), so without them both are conserved to round-off whatever the
//   deformation does. x then moves with the new v.
// - The angular velocity follows from L: omega = R I(q)^-1 (R^T L - h), with the deformed
//   inertia I(q) and the deformation's own angular momentum h = \int rho p x p' (the model's
//   RIGID_BODY moments give both exactly). R turns by the implicit midpoint rule (move()), which
//   keeps |L_b| and the rotational energy exactly at any step.
// - The deformation feels the frame's inertial forces -U^T M (omega x (omega x p) + omega' x p
//   + 2 omega x p'), with omega = I(q)^-1 L_b and L_b = R^T L - h held over the step. Of them:
//   - centrifugal, as the potential V(q) = L_b . I(q)^-1 L_b / 2 (the rotational energy at that
//     angular momentum), whose gradient is exactly the centrifugal force. It is a state force
//     (loads.h): implicit, in the minimising step's energy, so that spinning and vibrating trade
//     energy without making any;
//   - Euler, omega' x p, is left out: the basis is M-orthogonal to the rigid rotations, so
//     U^T M (omega' x (X - c)) = 0 and what is left, omega' x U q, is second order in the
//     deformation. Taken explicitly (omega' by difference over the last step) it pumped energy
//     into fast spins (a bar at 200 rad/s in 1/480 s steps: 190-fold in 2.3 s);
//   - Coriolis, 2 omega x p', is left out: it is gyroscopic (no work), second order in the
//     deformation for a basis M-orthogonal to the rigid motions, and taken explicitly it pumps
//     energy into the vibration (measured: a tumbling bar's energy grew 7x in 5 s).
//   What the step's turn and the deformation's new h change in V between the steps is settled
//   after q's step in free flight (turnExcess(), qv_instance::takeOutTurnExcess()), so that a
//   fast spin cannot feed the vibration step after step; with contacts in reach, they take it out.
//   Where the body turns more than 0.75 rad in a step, the move and q's step go in substeps
//   (qv_instance::finishStep()).
//   External forces act on all three: F and x_v x f on the frame, U_v^T R^T f on q.
#include "model.h"

namespace quiver::rt {

struct RigidFrame {
  double position[3] = {};         // x, m, the centre of mass in the world
  double orientation[4] = {1, 0, 0, 0};  // unit quaternion w, x, y, z: body to world
  double velocity[3] = {};         // v, m/s
  double angularMomentum[3] = {};  // L, kg m^2/s, about x, in the world
  double rotation[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};  // R from `orientation`, row-major
  double bodyOmega[3] = {};        // omega in the body frame at the current state
  double inertia[9] = {};          // I(q), body frame, at the current state
  double internal[3] = {};         // h = \int rho p x p', body frame, at the current state
  double force[3] = {}, torque[3] = {};  // this step's, world; torque about x
  double gravity[3] = {};          // persistent acceleration, m/s^2, world
  double homePosition[3] = {};     // where a reset puts the frame (the last set state), at rest
  double homeOrientation[4] = {1, 0, 0, 0};
  double* moments = nullptr;       // 9 x r: y_ab = \int rho p_a U_b at the current state
  double* products = nullptr;      // 9 x r: A_ab^T q at the centrifugal potential's trial q, then
                                   // 6 x r for its Hessian
  double heldMomentum[3] = {};     // L_b = R^T L - h, body frame, held over a step (holdSpin())
  double heldAngularMomentum[3] = {};  // L when it was held (spinChangedSinceHold())
  // J the turns took from the centrifugal potential, which later turns may give back; negative:
  // what they added that q' could not give, owed by the next steps.
  double turnCredit = 0;

  static size_t scratchDoubles(int r) { return 24 * static_cast<size_t>(r); }
  // Takes its scratch from `scratch` (scratchDoubles(r) doubles).
  void attach(double* scratch, int r);
  void setOrientation(const double quaternion[4]);  // normalises, updates `rotation`
  // A unit quaternion as it is (a snapshot's: normalised again, its last bits could move), and
  // `rotation` from it.
  void takeOrientation(const double unit[4]);
  // Brings moments, rates and bodyOmega up to date with the frame and (q, q').
  void refresh(const qv_model& model, const double* q, const double* qdot);
  // |omega| at L as it stands (after this step's torque and contact impulses), with h of the last
  // refresh() and I(q) of it or of the rest shape, whichever turns faster.
  double spinRate(const qv_model& model) const;
  // The world angular velocity R bodyOmega.
  void worldOmega(double omega[3]) const;
  // Sets L so that the world angular velocity is `omega` at (q, q') (refresh() first).
  void setWorldOmega(const double omega[3]);
  // Holds L_b = R^T L - h for this step's centrifugal potential (refresh() first).
  void holdSpin();
  // What the step's turn and the deformation's new h added to the centrifugal potential at the
  // step's end (q, q'), with L as held (no torque or contact since holdSpin()): V(q) at the L_b the
  // next step holds, less V(q) at the L_b this step held, or 0 within rounding. refresh()es at
  // (q, q').
  double turnExcess(const qv_model& model, const double* q, const double* qdot);
  // Whether L changed since holdSpin() (a torque or a contact impulse).
  bool spinChangedSinceHold() const {
    return angularMomentum[0] != heldAngularMomentum[0] || angularMomentum[1] != heldAngularMomentum[1] ||
           angularMomentum[2] != heldAngularMomentum[2];
  }
  // The centrifugal potential V(q) = L_b . I(q)^-1 L_b / 2: adds its gradient to `resisting` (the
  // resisting sign of loads.h) and its Hessian to `jacobian`; returns V.
  double addCentrifugal(const qv_model& model, const double* q, double* resisting, double* jacobian) const;
  // The frame's share of the step: momenta by this step's force, torque and gravity (accelerate),
  // then x and R (move); contact impulses go between the two.
  void accelerate(const qv_model& model, double h);
  void move(double h);
  // Orientation `from` turned by the Cayley map of t omega: 2 atan(t |omega| / 2) about the world
  // axis omega.
  void turn(const double from[4], const double omega[3], double t);
  // World position of body point p: x + R p.
  void toWorld(const double p[3], double out[3]) const;
  // Body direction of world vector f: R^T f; and back, R v.
  void toBody(const double f[3], double out[3]) const;
  void toWorldDirection(const double v[3], double out[3]) const;
  // The world's inverse inertia on w, R I^-1 R^T w (I of the last refresh()); and as a matrix
  // (row-major, symmetric), for many products at one pose (a contact solve).
  void inverseInertia(const double w[3], double out[3]) const;
  void inverseInertiaMatrix(double out[9]) const;
  // Kinetic energy of the frame's motion and its coupling to q': m |v|^2 / 2 + omega . (I omega / 2
  // + h) (refresh() first); with |q'|^2 / 2 the body's whole kinetic energy.
  double kineticEnergy(const qv_model& model) const;
  void goHome();  // the home pose, at rest
  bool finite() const;
};

} // namespace quiver::rt
