#pragma once
// The contacts of a step (contact.h), and the last step's, kept to warm-start the next: a contact
// seen again (same vertex against the same collider or body) starts from the impulse it ended with,
// so that a stack's impulses converge over steps rather than restarting from zero each step. And
// the step's pairs (a body against a collider or another body), whose candidates it counts by level
// (contact_points.h) to keep a spread subset of each when they do not all fit.
#include "contact_points.h"

namespace quiver::rt {

struct Contact {
  int body = 0;              // whose vertex
  int other = -1;            // the body it touches, or -1 for a collider
  int vertex = 0;            // body's vertex
  int otherVertex = 0;       // other's surface vertex nearest the contact, which takes the reaction
  int collider = -1;
  double point[3] = {}, normal[3] = {};  // normal: out of the collider or the other body
  double arm[3] = {}, otherArm[3] = {};  // point - x of body and of other
  double surfaceVelocity[3] = {};        // a kinematic collider's at the point
  double depth = 0;          // signed distance of the rigid shape's vertex, or with soft contacts of the
                             // deformed vertex (to the other's deformed surface); negative: penetrating
  bool speculative = false;  // depth beyond the slop: not touching yet
  int slot = 0;              // in a full list, of two equally poor the lower slot goes first (admit())
  double deformedDepth = 0;  // of the deformed vertex, reported
  double target = 0;         // the relative normal velocity the impulse aims at
  double bounce = 0;         // restitution x the approach speed: the target once the contact holds
  double normalImpulse = 0;  // accumulated, N s, on body (other takes its opposite)
  double stopImpulse = 0;    // what it was before the bounce: the part that stops the approach
  double restingImpulse = 0; // beyond it the contact is stiff: what resting under a stack takes
  double tangentImpulse[2] = {};
  double tangent[2][3] = {};
  double normalMass = 0, tangentMass[2] = {};
  double friction = 0, restitution = 0;
  // Where a side's deformation gives way (contact_modes.h): its vertex's rows of U V; null without
  // soft contacts on that side, and in a bounce.
  const double* rows = nullptr;
  const double* otherRows = nullptr;
};

// A contact's directions (normal, tangent 0, tangent 1) in the solve: the spin a unit impulse along
// each gives its body, I^-1 (arm x d), and the other body (at its own arm), so that each impulse
// costs the solve a few multiply-adds. Formed once a solve; not kept from step to step.
struct ContactTurns {
  double body[3][3] = {}, other[3][3] = {};
};

// Contacts by who touches what where: the warm start finds last step's by it, and the solve runs
// in its order whichever contacts the capacity kept.
inline bool keyBefore(const Contact& x, const Contact& y) {
  if (x.body != y.body) return x.body < y.body;
  if (x.other != y.other) return x.other < y.other;
  if (x.collider != y.collider) return x.collider < y.collider;
  return x.vertex < y.vertex;
}

// One body's candidate contacts with one collider or one other body in a step.
struct ContactPair {
  int body = 0, other = -1, collider = -1;
  int count[kContactLevels] = {};  // candidates by level
  int minLevel = 0;  // kept: candidates of this level and above
  // Its deep contacts (keepConsistentPushes(), contact.cpp): their normals each times its depth,
  // the sum of their depths, and the normal of the shallowest (exitDepth its depth).
  double push[3] = {}, weight = 0, exit[3] = {}, exitDepth = 0;
};

// Where a solve puts its contacts: `contacts` this step's, `previous` the last step's (sorted by
// key); two arrays of `capacity` that trade places each step; `turns`, `order` and `pairs`, `capacity` more.
struct ContactList {
  Contact* contacts = nullptr;
  Contact* previous = nullptr;
  ContactTurns* turns = nullptr;  // contacts' (the solve's)
  int* order = nullptr;           // the solve's: the contacts by island
  ContactPair* pairs = nullptr;
  int count = 0, previousCount = 0, capacity = 0;
  int pairCount = 0;
  int touching = 0;       // candidates within the slop this step, kept or not
  bool reducing = false;  // finding again, each pair down to its minLevel
  bool full = false;      // contacts[0, count) is a heap with the one to give up first on top (admit())

  void clear() {
    count = previousCount = 0;
    full = false;
  }
};

// The last step's contacts as a snapshot carries them: what the next step warm-starts from and
// what qv_instance_contacts reports, kContactRecord doubles each after their count.
constexpr size_t kContactRecord = 20;
// Writes the count and the records; returns the doubles written.
size_t saveContacts(const ContactList& list, double* out);
// How many doubles the contacts at `in` take (their count and records), or 0 where they are not a
// list a step of `bodies` (their indices' order) among `colliderCount` colliders could have ended
// with: the count within the list's capacity and the `available` doubles, each record finite, of a
// body and its vertex, and another body or a collider, with unit normal and tangents and a
// non-negative normal impulse, in the solve's order (no key twice).
size_t validContacts(const double* in, size_t available, const ContactList& list, const qv_instance* const* bodies,
                     int bodyCount, int colliderCount);
// x as an index in [low, high) (a number a snapshot holds), or -2 where it is not one.
inline int indexIn(double x, int low, int high) {
  return x >= low && x < high && x == static_cast<double>(static_cast<long long>(x)) ? static_cast<int>(x) : -2;
}
// Makes them the last step's (validContacts() first).
void restoreContacts(ContactList& list, const double* in);

} // namespace quiver::rt
