#pragma once
// Contact of flying instances with the world's colliders (qv_collider: plane, sphere, box, capsule,
// triangle mesh; the caller's array, which it may move between steps) and with each other. An
// object's surface vertices are its contact points; another object is its rest surface carried by
// its frame (the model's surface mesh, triangle_mesh.h).
//
// Each step, between the frames' velocity updates and their moves (rigid_frame.h):
// - every surface vertex within reach of a collider or another object (its signed distance below a
//   speculative margin: twice what the two cover relative to each other in the step, or what the
//   fastest relative motion in its group covers, as the solve can stop or push either) is a contact,
//   up to a capacity: when more are found, each pair (a body against a collider or another body)
//   keeps its vertices down to a level (contact_points.h), a subset spread over its patch; the
//   pairs with the most give up levels first;
// - a vertex deeper than resting contacts sink (spawned or pushed deep inside) takes whichever face
//   is nearest, so each pair keeps only its deep contacts that push along the pair's mean push
//   (opposed pushes grew without bound and flung the bodies off);
// - sequential impulses (24 sweeps at most, an island of bodies stopping once its impulses settle)
//   on the frames' velocities and angular momenta: a normal impulse
//   >= 0 that stops the approach where the surfaces meet (so nothing tunnels while it is seen) and
//   pushes out what penetrates beyond a slop (at 1 m/s at most), slightly soft so that a resting face shares its weight
//   by depth; from the middle sweep on, contacts that push aim at the bounce (restitution x the
//   approach speed, when faster than the step's gravity gives); a tangent impulse within the Coulomb
//   disc mu * normal. Velocity-level constraints: stiff contact at any time step, no penalty
//   stiffness to tune. The frames' velocities alone (not the deformation's) enter: impulses on the
//   frame cannot change the deformation's, and chasing it pumped energy; a kinematic collider's
//   surface velocity does;
// - with soft contacts (qv_instance_config::soft_contacts), a body's contacts hold its deformed
//   vertices (against colliders, each one's margin covers its deformation's speed too; between
//   bodies, the frames' alone), and its deformation enters as well, as the implicit step will
//   move it: its motion without new contact forces (qv_instance::predictContactModes()), and each
//   impulse's through the step's compliance, diagonal in the model's contact modes
//   (contact_modes.h); not in a bounce, which stays the frames';
// - the same impulses, over the step, act on q as vertex forces (so the object squashes where it
//   lands and sags where it rests), a bounded load for the implicit step; less the bounce, which the
//   restitution already returns to the frame (loading q with it too made a bounce gain 31%). The
//   object touched takes the opposite force at its surface vertex nearest the contact.
#include "broad_phase.h"
#include "contact_list.h"
#include "instance.h"

namespace quiver::rt {

// A flying instance in a contact solve: its frame's velocity and spin as the impulses change them
// (the angular momenta they add go to the frame once the solve ends).
struct ContactBody {
  qv_instance* instance = nullptr;
  double velocity[3] = {}, inverseMass = 0;
  double omega[3] = {};  // the world angular velocity before the solve
  // In the solve: the world angular velocity its impulses so far give (omega + I^-1 of the angular
  // momentum they added), and the world inverse inertia they act through (RigidFrame's, held while
  // the frame does not move), which each contact's directions are turned through once a solve
  // (ContactTurns).
  double spin[3] = {};
  double inverseInertia[9] = {};
  // In the solve: the island it is in (the lowest index of the bodies its contacts join), and at an
  // island's index whether one of its contacts bounces and where its contacts are in ContactList::order.
  int island = 0;
  bool islandBounces = false;
  int islandFirst = 0, islandEnd = 0;
  int firstPair = 0, pairEnd = 0;  // its pairs in the contact list
  // Its group: the bodies it could touch in the step (either stopped), and the ones those could
  // touch. The fastest relative speed of one of them against what it could touch sets its
  // speculative margins (spreadSpeeds(), contact.cpp). ownSpeed: its surface's, in the world.
  // Its root after a solve or wakeSleepers(); `wakes`: a root whose group wakes.
  int group = 0;
  double ownSpeed = 0, touchSpeed = 0, groupSpeed = 0;
  bool wakes = false;
  bool nearMovingCollider = false;  // one with a velocity is within its reach
  bool modesPredicted = false;      // soft contacts: its deformation's motion predicted this solve
};

// Friction and restitution between two instances (a collider brings its own).
struct ContactMaterial {
  double friction = 0.5, restitution = 0;
};

// Signed distance of `p` to `collider` and the outward normal there; false for an invalid
// collider, or (meshes) when p is farther than `reach` from it. With `facing` (a world direction),
// a box or a mesh counts only its faces facing against it (qv_triangle_mesh::distance); false when
// none does.
bool colliderDistance(const qv_collider& collider, const double p[3], double reach, double& distance, double normal[3],
                      const double* facing = nullptr);
bool validCollider(const qv_collider& collider);

// Whether a's contact points (rest or, with soft contacts, deformed: qv_instance::surfaceLow),
// carried by its frame, all lie farther than `margin` from b's rest surface: the boxes around them
// in their bodies' axes are farther apart than that along one of the six face normals (the
// separating axes of two boxes that need no cross product), by more than rounding. In a pile most
// bars near enough for their spheres are apart so, and each of a's vertices would be a
// closest-point query that finds nothing.
bool boxesApart(const qv_instance& a, const qv_instance& b, double margin);
// A soft body's contact points as its deformation places them, in its body axes, and their box
// (qv_instance::deformedSurface, surfaceLow): once a contact search, not for each body it could touch.
void deformSurface(qv_instance& s);

// The solve starts from the frames' momenta as their velocity updates left them: takes them into
// `bodies`, and groups the bodies and spreads their speeds (contact.cpp, spreadSpeeds()). Call
// after the frames' velocity updates, before wakeSleepers() and solveContacts(), and again after
// wakeSleepers() woke some.
void takeMomenta(ContactBody* bodies, int count, const qv_collider* colliders, int colliderCount, double h,
                 BroadPhase* broad = nullptr);

// Finds the step's contacts of `bodies` with `colliders` and with each other, solves their
// impulses into the frames' velocities and angular momenta, and adds their forces on q. Call after
// takeMomenta(), before the frames move; all bodies share the time step h. Sleeping
// bodies (qv_instance::asleep, at rest) take no part: none may be within an awake body's reach
// (wakeSleepers()). With `broad` (a world's), the pairs of bodies tested are its overlaps
// (broad_phase.h); without, every pair. With `jobs`, the islands' sweeps run in them.
void solveContacts(ContactBody* bodies, int bodyCount, const qv_collider* colliders, int colliderCount,
                   const ContactMaterial& between, ContactList& list, double h, BroadPhase* broad = nullptr,
                   const qv_job_runner* jobs = nullptr);

// Wakes every sleeping body whose group (takeMomenta()'s, as the solve will group them) holds an
// awake body or meets a moving collider, and every one within an awake body's margin; returns how
// many. Woken bodies start their step and move: take the momenta and call again until it wakes none.
int wakeSleepers(ContactBody* bodies, int count, double h, BroadPhase* broad = nullptr);

} // namespace quiver::rt
