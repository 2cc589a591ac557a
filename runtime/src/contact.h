#pragma once
// Contact of a flying instance with the world's colliders (qv_collider: plane, sphere, box,
// capsule; the caller's array, which it may move between steps). The object's surface vertices
// are its contact points.
//
// Each step, between the frame's velocity update and its move (rigid_frame.h):
// - every surface vertex within reach of a collider (its signed distance below what the frame's
//   motion can cover in the step, a speculative margin) is a contact, up to max_contacts (the
//   deepest kept);
// - sequential impulses (24 sweeps) on the frame's velocity and angular momentum: a normal impulse
//   >= 0 that stops the approach where the surfaces meet (so nothing tunnels while it is seen) and
//   pushes out what penetrates beyond a slop, slightly soft so that a resting face shares its weight
//   by depth; from the middle sweep on, contacts that push aim at the bounce (restitution x the
//   approach speed, when faster than the step's gravity gives); a tangent impulse within the Coulomb
//   disc mu * normal. Velocity-level constraints: stiff contact at any time step, no penalty
//   stiffness to tune. The frame's velocity alone (not the deformation's) enters: impulses on the
//   frame cannot change the deformation's, and chasing it pumped energy;
// - the same impulses, over the step, act on q as vertex forces (so the object squashes where it
//   lands and sags where it rests), a bounded load for the implicit step; less the bounce, which the
//   restitution already gives back to the frame (loading q with it too made a bounce gain 31%).
#include "instance.h"

namespace quiver::rt {

struct Contact {
  int vertex = 0, collider = 0;
  double point[3] = {}, normal[3] = {};
  double arm[3] = {};        // point - x
  double depth = 0;          // signed distance of the rigid shape's vertex (negative: penetrating)
  double deformedDepth = 0;  // of the deformed vertex, reported
  double target = 0;         // the normal velocity the impulse aims at
  double bounce = 0;         // restitution x the approach speed: the target once the contact holds
  double normalImpulse = 0;  // accumulated, N s
  double stopImpulse = 0;    // what it was before the bounce: the part that stops the approach
  double tangentImpulse[2] = {};
  double tangent[2][3] = {};
  double normalMass = 0, tangentMass[2] = {};
};

// Signed distance of `p` to `collider` and the outward normal there; false for an invalid collider.
bool colliderDistance(const qv_collider& collider, const double p[3], double& distance, double normal[3]);
bool validCollider(const qv_collider& collider);

// Finds the step's contacts and solves their impulses into the frame's velocity and angular
// momentum; adds their forces on q. Call after the frame's velocity update, before it moves.
void solveContacts(qv_instance& s, double h);

} // namespace quiver::rt
