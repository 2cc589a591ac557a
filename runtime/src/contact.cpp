#include "contact.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstring>
#include <utility>

#include "c_enum.h"
#include "jobs.h"
#include "triangle_mesh.h"
#include "vec3.h"

namespace quiver::rt {

namespace {

constexpr double kSoftness = 0.1;
constexpr int kSweeps = 24;  // at most
// A sweep that changes none of an island's impulses by more than this fraction of what resting
// takes (restingImpulse) ends the island's solve: such a sweep moved its contacts by about 1e-8 m/s
// each. At rest the warm start leaves 1e-16 (a bar alone) to 1e-7 (in a pile of 80) for the first
// sweep, which later sweeps shrink by 10% or less each; a landing or a slide changes them by
// whole fractions and takes all the sweeps.
constexpr double kConverged = 1e-8;
constexpr double kMaxPushOut = 1.0;  // m/s: the fastest a deep penetration is pushed out
// rad: past this turn in a step, a vertex's straight path strays from its arc by an eighth of its
// arm. A contact's margin takes the path as straight, at the vertex's velocity, which for a turn of
// radians overshoots the arc: a bar spun at 250 rad/s, its ends 0.2 m above the ground, had them
// stopped at the ground they swing past, and was thrown off it (at 1000 rad/s, 186 m up). But the
// vertex stays within its arm of the body's centre, which moves straight, and a signed distance
// changes no faster than the point moves relative to the surface: past this turn a vertex is kept
// only where the centre's distance, less the arm and that relative travel (twice over the step, as
// the margins take it), can close.
constexpr double kStraightTurn = 0.5;

bool finiteAll(const double* v, int n) {
  for (int i = 0; i < n; ++i)
    if (!std::isfinite(v[i])) return false;
  return true;
}

// Distance from p to c along d (|d| > 0), normal d / |d|; +z where p is at c.
double away(const double p[3], const double c[3], double normal[3]) {
  const double d[3] = {p[0] - c[0], p[1] - c[1], p[2] - c[2]};
  const double len = norm3(d);
  for (int a = 0; a < 3; ++a) normal[a] = len > 0 ? d[a] / len : (a == 2 ? 1.0 : 0.0);
  return len;
}

// A collider's turn (Rodrigues' formula on its rotation vector), row-major; false when it has none.
bool colliderRotation(const qv_collider& c, double R[9]) {
  const double* w = c.rotation;
  const double angle = norm3(w);
  if (!(angle > 0)) return false;
  const double k[3] = {w[0] / angle, w[1] / angle, w[2] / angle}, s = std::sin(angle), v = 1 - std::cos(angle);
  R[0] = 1 + v * (k[0] * k[0] - 1), R[1] = v * k[0] * k[1] - s * k[2], R[2] = v * k[0] * k[2] + s * k[1];
  R[3] = v * k[0] * k[1] + s * k[2], R[4] = 1 + v * (k[1] * k[1] - 1), R[5] = v * k[1] * k[2] - s * k[0];
  R[6] = v * k[0] * k[2] - s * k[1], R[7] = v * k[1] * k[2] + s * k[0], R[8] = 1 + v * (k[2] * k[2] - 1);
  return true;
}

// Where the collider's angular velocity turns it about (qv_collider's `velocity`).
void referencePoint(const qv_collider& c, double out[3]) {
  const double* d = c.data;
  if (c.type == QV_COLLIDER_PLANE) {
    const double s = d[3] / dot3(d, d);
    for (int a = 0; a < 3; ++a) out[a] = s * d[a];
  } else {
    for (int a = 0; a < 3; ++a) out[a] = d[a];
  }
}

// The velocity of a kinematic collider's surface at p.
void surfaceVelocity(const qv_collider& c, const double p[3], double out[3]) {
  double ref[3], rel[3], turn[3];
  referencePoint(c, ref);
  for (int a = 0; a < 3; ++a) rel[a] = p[a] - ref[a];
  cross3(c.angular_velocity, rel, turn);
  for (int a = 0; a < 3; ++a) out[a] = c.velocity[a] + turn[a];
}

// Axis-aligned box centred at the origin with half extents e: distance of p and the outward normal.
double boxDistance(const double p[3], const double e[3], double normal[3]) {
  double q[3], outside = 0, inside = -INFINITY;
  int deepest = 0;
  for (int a = 0; a < 3; ++a) {
    q[a] = std::fabs(p[a]) - e[a];
    outside += q[a] > 0 ? q[a] * q[a] : 0;
    if (q[a] > inside) inside = q[a], deepest = a;
  }
  if (outside > 0) {
    const double distance = std::sqrt(outside);
    for (int a = 0; a < 3; ++a) normal[a] = (q[a] > 0 ? q[a] : 0) * (p[a] >= 0 ? 1 : -1) / distance;
    return distance;
  }
  for (int a = 0; a < 3; ++a) normal[a] = a == deepest ? (p[a] >= 0 ? 1 : -1) : 0;
  return inside;
}

// The same, counting only the faces facing against `facing`: the distance to the nearest of them
// (its rectangle), negative on the inner side of its plane, and its normal; false when none does.
bool boxFacingDistance(const double p[3], const double e[3], const double facing[3], double& distance, double normal[3]) {
  double best = INFINITY;
  for (int axis = 0; axis < 3; ++axis)
    for (const double side : {-1.0, 1.0}) {
      if (side * facing[axis] >= 0) continue;
      double d2 = 0;
      for (int a = 0; a < 3; ++a) {
        const double along = a == axis ? p[a] - side * e[a] : std::fabs(p[a]) - e[a];
        if (a == axis || along > 0) d2 += along * along;
      }
      if (d2 >= best) continue;
      best = d2;
      distance = side * (p[axis] - side * e[axis]) < 0 ? -std::sqrt(d2) : std::sqrt(d2);
      for (int a = 0; a < 3; ++a) normal[a] = a == axis ? side : 0;
    }
  return best < INFINITY;
}

// The spin an impulse along d at arm a gives a body per unit, I^-1 (a x d), into `turn`; returns
// 1/m + (a x d) . I^-1 (a x d), the inverse of the mass the impulse meets there.
double turnPerImpulse(const ContactBody& b, const double a[3], const double d[3], double turn[3]) {
  double ad[3];
  cross3(a, d, ad);
  multiply3(b.inverseInertia, ad, turn);
  return b.inverseMass + dot3(ad, turn);
}

// The frame's velocity at a point with arm a, as the solve's impulses so far leave it.
void bodyPointVelocity(const ContactBody& b, const double a[3], double out[3]) {
  double wa[3];
  cross3(b.spin, a, wa);
  for (int k = 0; k < 3; ++k) out[k] = b.velocity[k] + wa[k];
}

// The impulse J = sum_k lambda_k d_k along a contact's directions (normal, tangent 0, tangent 1).
void impulseAlong(const Contact& ct, const double lambda[3], double J[3]) {
  for (int a = 0; a < 3; ++a) J[a] = lambda[0] * ct.normal[a] + lambda[1] * ct.tangent[0][a] + lambda[2] * ct.tangent[1][a];
}

// That impulse (impulseAlong()), times sign, on a body's velocity and spin; `turns`: the
// turnPerImpulse() of each direction at its arm.
void applyImpulse(ContactBody& b, const double turns[3][3], const double lambda[3], const double J[3], double sign) {
  for (int k = 0; k < 3; ++k) {
    b.velocity[k] += sign * b.inverseMass * J[k];
    b.spin[k] += sign * (lambda[0] * turns[0][k] + lambda[1] * turns[1][k] + lambda[2] * turns[2][k]);
  }
}

// Mode i's share of body vector d at a contact point whose rows of U V are `rows` (contact_modes.h):
// ((U V)_v^T d)_i.
double modeShare(const double* rows, int r, int i, const double d[3]) {
  return rows[i] * d[0] + rows[r + i] * d[1] + rows[2 * r + i] * d[2];
}

// A contact side's deformation in the contact modes, at its vertex, whose rows of U V are `rows`:
// its velocity over the step so far (world), as predicted and as the solve's impulses change it ...
void modeVelocityAt(const qv_instance& s, const double* rows, double out[3]) {
  const int r = s.r;
  double local[3] = {};
  for (int a = 0; a < 3; ++a)
    for (int i = 0; i < r; ++i) local[a] += rows[a * r + i] * s.modeVelocity[i];
  s.frame.toWorldDirection(local, out);
}

// ... how far it gives way along d (world) per unit impulse along d, g^T diag(c) g, g = (U V)_v^T R^T d ...
double modeGiving(const qv_instance& s, const double* rows, const double d[3]) {
  double n[3], sum = 0;
  s.frame.toBody(d, n);
  for (int i = 0; i < s.r; ++i) {
    const double g = modeShare(rows, s.r, i, n);
    sum += s.modeCompliance[i] * g * g;
  }
  return sum;
}

// ... and an impulse J (world) on it.
void pushModes(qv_instance& s, const double* rows, const double J[3], double sign) {
  double n[3];
  s.frame.toBody(J, n);
  for (int i = 0; i < s.r; ++i) s.modeVelocity[i] += sign * s.modeCompliance[i] * modeShare(rows, s.r, i, n);
}

// Vertex v of a body's rest shape, carried by its frame (or deformed by q when `deformed`).
void worldVertex(const qv_instance& s, int v, bool deformed, double out[3]) {
  const qv_model& m = *s.model;
  double body[3], u[3] = {};
  if (deformed) m.vertexLinear(v, s.q, u, nullptr);
  for (int a = 0; a < 3; ++a) body[a] = m.rest[3 * v + a] - m.rigidBody[a] + u[a];
  s.frame.toWorld(body, out);
}

// Contact point n of a body (its surface vertex), carried by its frame: of its rest shape, or
// deformed by q where `deformed` (a soft body's as its last deformSurface() placed them).
void surfacePoint(const qv_instance& s, int n, bool deformed, double out[3]) {
  if (deformed && s.deformedSurface) {
    s.frame.toWorld(s.deformedSurface + 3 * n, out);
  } else {
    worldVertex(s, s.surfaceVertices[n], deformed, out);
  }
}

// Signed distance of world point p to a body's rest surface carried by its frame; the surface
// vertex nearest the closest point through `vertex`, the triangle through `nearest`. False when
// beyond `reach`. With `facing` (a world direction), to the surface facing against it only; `hint`,
// a triangle likely nearest (qv_triangle_mesh::distance).
bool bodyDistance(const qv_instance& s, const double p[3], double reach, double& distance, double normal[3], int* vertex,
                  const double* facing = nullptr, int* nearest = nullptr, int hint = -1) {
  const qv_model& m = *s.model;
  double rel[3], local[3], n[3], localFacing[3];
  for (int a = 0; a < 3; ++a) rel[a] = p[a] - s.frame.position[a];
  s.frame.toBody(rel, local);
  for (int a = 0; a < 3; ++a) local[a] += m.rigidBody[a];  // the mesh is in the model's rest coordinates
  if (facing) s.frame.toBody(facing, localFacing);
  int triangle = 0;
  if (!m.surfaceMesh->distance(local, reach, distance, n, &triangle, facing ? localFacing : nullptr, hint)) return false;
  if (nearest) *nearest = triangle;
  s.frame.toWorldDirection(n, normal);
  if (vertex) {
    double best = INFINITY;
    for (int k = 0; k < 3; ++k) {
      const int v = m.surfaceMesh->triangles[3 * triangle + k];
      double d2 = 0;
      for (int a = 0; a < 3; ++a) d2 += (m.rest[3 * v + a] - local[a]) * (m.rest[3 * v + a] - local[a]);
      if (d2 < best) best = d2, *vertex = v;
    }
  }
  return true;
}

// Body b's pair with a collider or another body; in the first pass a new one when it has none
// yet (null when the table is full: its candidates then compete by depth alone).
ContactPair* findPair(ContactList& list, ContactBody& b, int body, int other, int collider) {
  for (int p = b.firstPair; p < b.pairEnd; ++p)
    if (list.pairs[p].other == other && list.pairs[p].collider == collider) return &list.pairs[p];
  if (list.reducing || list.pairCount == list.capacity) return nullptr;
  ContactPair& pair = list.pairs[list.pairCount++];
  pair = ContactPair{};
  pair.body = body, pair.other = other, pair.collider = collider;
  b.pairEnd = list.pairCount;
  return &pair;
}

// Which of two contacts a full list gives up first: a speculative one before a touching one, then
// the shallower, then the one in the lower slot, a newcomer taking the slot of the one it replaces
// (as a scan of the slots in order would pick: on a flat face resting on the ground, where many
// are equally deep, ties broken by who touches what kept one end of it and it rocked).
bool givenUpFirst(const Contact& x, const Contact& y) {
  if (x.speculative != y.speculative) return x.speculative;
  if (x.depth != y.depth) return x.depth > y.depth;
  return x.slot < y.slot;
}

// A heap with the contact given up first on top: moves heap[i] down to where it belongs; returns
// where that is.
int siftDown(Contact* heap, int count, int i) {
  // The children move up into the hole it leaves, and it is copied once where it stops: a Contact
  // is some 300 bytes, which a swap at each level copied three times.
  const Contact moving = heap[i];
  for (;;) {
    int top = -1;
    for (int c = 2 * i + 1; c <= 2 * i + 2 && c < count; ++c)
      if (givenUpFirst(heap[c], top < 0 ? moving : heap[top])) top = c;
    if (top < 0) break;
    heap[i] = heap[top];
    i = top;
  }
  heap[i] = moving;
  return i;
}

void makeHeap(Contact* heap, int count) {
  for (int i = count / 2 - 1; i >= 0; --i) siftDown(heap, count, i);
}

// Where a candidate contact goes, with who touches what where filled in; null when it is not kept.
// Touching candidates (within the slop) come before speculative ones (farther, within the step's
// reach), and the deeper first: a full list gives up its shallowest speculative contact, then its
// shallowest. The first pass counts the touching by pair and level; when more touch than fit, the
// second keeps each pair's down to its minLevel (keepLevels()), spread over its patch, not the
// deepest: those sat on one side of a resting face, then on the other as it tilted, and it rocked
// forever. (Keeping each pair's deepest as well made it rock again: that vertex switched ends.)
Contact* admit(ContactList& list, ContactBody& b, int body, int other, int collider, int n, double depth) {
  const bool speculative = depth > b.instance->contactSlop;
  if (!speculative) {
    const int level = b.instance->surfaceLevels[n];
    ContactPair* pair = findPair(list, b, body, other, collider);
    if (!list.reducing) {
      ++list.touching;
      if (pair) ++pair->count[level];
    } else if (pair && level < pair->minLevel) {
      return nullptr;
    }
  }
  Contact candidate{};
  candidate.body = body, candidate.other = other, candidate.collider = collider, candidate.depth = depth;
  candidate.speculative = speculative, candidate.vertex = b.instance->surfaceVertices[n];
  Contact* slot = nullptr;
  if (list.count < list.capacity) {
    candidate.slot = list.count;
    slot = &list.contacts[list.count++];
    *slot = candidate;
  } else if (list.capacity) {
    // Full: the one to give up first is the top of a heap. A scan for it made every candidate past
    // the capacity cost the whole list (a pile of 80 bars, 5120 contacts: 120 ms frames).
    if (!list.full) makeHeap(list.contacts, list.count);
    list.full = true;
    candidate.slot = list.contacts[0].slot;
    if (!givenUpFirst(list.contacts[0], candidate)) return nullptr;
    list.contacts[0] = candidate;
    slot = &list.contacts[siftDown(list.contacts, list.count, 0)];
  }
  return slot;
}

int keptOf(const ContactPair& p) {
  int kept = 0;
  for (int l = p.minLevel; l < kContactLevels; ++l) kept += p.count[l];
  return kept;
}

// Levels for each pair so that its touching candidates fit: the pair that keeps the most gives up its
// lowest level, until they fit, while that leaves it at least kMinKept (a patch of a few vertices
// keeps them all while a face of hundreds thins out; levels are spread over the whole surface, so a
// small patch could otherwise lose every vertex). What still does not fit goes by depth (admit()).
void keepLevels(ContactList& list) {
  constexpr int kMinKept = 4;
  int total = list.touching;  // every pair keeps all to begin with
  while (total > list.capacity) {
    ContactPair* richest = nullptr;
    int most = 0;
    for (int p = 0; p < list.pairCount; ++p) {
      ContactPair& pair = list.pairs[p];
      const int kept = keptOf(pair);
      if (pair.minLevel < kContactLevels - 1 && kept - pair.count[pair.minLevel] >= kMinKept && kept > most)
        richest = &pair, most = kept;
    }
    if (!richest) break;
    total -= richest->count[richest->minLevel++];
  }
}

// How fast body b's surface can move relative to something moving at `velocity`: the frame's
// relative velocity plus its spin at its farthest vertex.
double relativeSpeed(const ContactBody& b, const double velocity[3]) {
  const double d[3] = {b.velocity[0] - velocity[0], b.velocity[1] - velocity[1], b.velocity[2] - velocity[2]};
  return norm3(d) + norm3(b.omega) * b.instance->surfaceRadius;
}

// How fast bodies a and b's surfaces can approach each other.
double pairSpeed(const ContactBody& a, const ContactBody& b) {
  return relativeSpeed(a, b.velocity) + norm3(b.omega) * b.instance->surfaceRadius;
}

// The broad phase's intervals: each body's centre and a half width bounding its reach, `reach(b)`,
// padded so that rounding cannot drop a pair the exact test would keep; a body whose reach is not
// a number (a non-finite velocity, which its step will reset) reaches everything, as the exact
// tests let it.
template <class Reach>
void sortByReach(const ContactBody* bodies, int count, BroadPhase& broad, Reach reach) {
  for (int i = 0; i < count; ++i) {
    const double* x = bodies[i].instance->frame.position;
    std::memcpy(broad.centres + 3 * i, x, 3 * sizeof(double));
    const double w = reach(bodies[i]);
    broad.halfWidth[i] = w <= DBL_MAX ? w + 1e-9 * (w + std::fabs(x[0]) + std::fabs(x[1]) + std::fabs(x[2])) : INFINITY;
  }
  sortIntervals(broad, count);
}

// Calls pair(i, j) once for each pair of bodies whose reaches, `reach(b)` from each centre,
// overlap along the broad phase's axis (with `broad`), or for every pair (without).
template <class Reach, class Pair>
void forEachCandidate(const ContactBody* bodies, int count, BroadPhase* broad, Reach reach, Pair pair) {
  if (broad) {
    sortByReach(bodies, count, *broad, reach);
    forEachOverlap(*broad, pair);
  } else {
    for (int i = 0; i < count; ++i)
      for (int j = i + 1; j < count; ++j) pair(i, j);
  }
}

// How far from its centre body b can touch another in the step, bodies grouped or not: its share
// of a pair's bound in spreadSpeeds() (the larger slop is at most both).
double groupingReach(const ContactBody& b, double h) {
  return b.instance->surfaceRadius + b.instance->contactSlop + 2 * h * b.ownSpeed;
}

// How far from its centre body b's contacts with others can reach: its share of any pair's
// margin (bodyMargin() <= the sum of both shares: a pair's speed is at most both speeds).
double contactReach(const ContactBody& b, double h) {
  return b.instance->surfaceRadius + b.instance->contactSlop + 2 * h * (b.ownSpeed + b.groupSpeed);
}

int groupOf(ContactBody* bodies, int i) {
  while (bodies[i].group != i) i = bodies[i].group = bodies[bodies[i].group].group;
  return i;
}

// Groups the bodies that could touch in the step (bounding spheres within what both cover, either
// stopped), and gives each the fastest relative speed in its group, of two of its bodies or of one
// and a collider within reach. Margins from a pair's relative speed at the step's start miss what
// the solve does to either: a pile's layers fell together, the ground stopped the lowest, and the
// next fell 5 cm into it; one hit from above pushed the one below it into the ground. A group that
// touches nothing moving otherwise (a pile falling together) keeps its margins.
void spreadSpeeds(ContactBody* bodies, int count, const qv_collider* colliders, int colliderCount, double h,
                  BroadPhase* broad) {
  const double still[3] = {};
  for (int i = 0; i < count; ++i) {
    ContactBody& b = bodies[i];
    const qv_instance& s = *b.instance;
    b.group = i, b.touchSpeed = 0, b.ownSpeed = relativeSpeed(b, still), b.nearMovingCollider = false;
    for (int k = 0; k < colliderCount; ++k) {
      double u[3], distance, normal[3];
      surfaceVelocity(colliders[k], s.frame.position, u);
      // The collider's spin moves its surface within reach faster than at the body's centre.
      const double speed = relativeSpeed(b, u) + norm3(colliders[k].angular_velocity) * s.surfaceRadius;
      if (!(speed > 0)) continue;  // adds nothing (a sleeper beside a still collider: no query)
      const double reach = s.surfaceRadius + s.contactSlop + 2 * h * speed;
      if (!colliderDistance(colliders[k], s.frame.position, reach, distance, normal) || distance > reach) continue;
      b.touchSpeed = std::fmax(b.touchSpeed, speed);
      b.nearMovingCollider |= dot3(colliders[k].velocity, colliders[k].velocity) > 0 ||
                              dot3(colliders[k].angular_velocity, colliders[k].angular_velocity) > 0;
    }
  }
  const auto pair = [&](int i, int j) {
    const qv_instance &a = *bodies[i].instance, &b = *bodies[j].instance;
    double gap[3];
    for (int k = 0; k < 3; ++k) gap[k] = a.frame.position[k] - b.frame.position[k];
    // Within reach if either stopped (their relative speed is never more than both speeds).
    if (norm3(gap) > a.surfaceRadius + b.surfaceRadius + std::fmax(a.contactSlop, b.contactSlop) +
                         2 * h * (bodies[i].ownSpeed + bodies[j].ownSpeed))
      return;
    const double speed = pairSpeed(bodies[i], bodies[j]);
    bodies[i].touchSpeed = std::fmax(bodies[i].touchSpeed, speed);
    bodies[j].touchSpeed = std::fmax(bodies[j].touchSpeed, speed);
    bodies[groupOf(bodies, i)].group = groupOf(bodies, j);
  };
  forEachCandidate(bodies, count, broad, [&](const ContactBody& b) { return groupingReach(b, h); }, pair);
  for (int i = 0; i < count; ++i) bodies[i].groupSpeed = 0;
  for (int i = 0; i < count; ++i) {
    ContactBody& root = bodies[groupOf(bodies, i)];
    root.groupSpeed = std::fmax(root.groupSpeed, bodies[i].touchSpeed);
  }
  for (int i = 0; i < count; ++i) {
    bodies[i].group = groupOf(bodies, i);
    bodies[i].groupSpeed = bodies[bodies[i].group].groupSpeed;
  }
}

// The margin of body i's vertices against body j's surface (findBodyContacts()), and whether their
// bounding spheres come within it.
double bodyMargin(const ContactBody* bodies, int i, int j, double h) {
  const qv_instance &a = *bodies[i].instance, &b = *bodies[j].instance;
  return std::fmax(a.contactSlop, b.contactSlop) + 2 * h * std::fmax(pairSpeed(bodies[i], bodies[j]), bodies[i].groupSpeed);
}

bool withinMargin(const ContactBody* bodies, int i, int j, double margin) {
  const qv_instance &a = *bodies[i].instance, &b = *bodies[j].instance;
  double gap[3];
  for (int k = 0; k < 3; ++k) gap[k] = a.frame.position[k] - b.frame.position[k];
  return norm3(gap) <= a.surfaceRadius + b.surfaceRadius + margin;
}

// How far from a surface a candidate can be and still be kept: a full list takes only those its
// poorest would give way to (admit()), so the closest-point queries need not look farther (in a
// pile of 320 bars they took half the step). Touching candidates (within the vertex's own slop,
// which differs from model to model) are always found: they are counted.
double keptReach(const ContactList& list, double margin, double slop) {
  if (!list.full) return margin;
  const Contact& poorest = list.contacts[0];
  return std::fmin(margin, poorest.speculative ? std::fmax(poorest.depth, slop) : slop);
}

// A touching vertex facing the same way as the surface it is nearest lies along it and cannot press
// on it: it presses on the nearest part of the surface that faces it, which `query(depth, normal)`
// measures against its outward pseudo-normal `own` (filled in here). Bars laid edge on edge had
// each rim vertex nearest the side face under the other's rim, and a bar laid flush with a box's
// edge each vertex of its side: those sideways normals rolled the stacked bars over, 13-23
// degrees, and the bar off the box. Not where that part is deeper than a touching contact sinks
// (3 slops and 2 g h^2, the soft contacts' most at rest, solveContacts()) beyond the margin: that
// is some other part of the surface. Returns whether it took that part's depth and normal (the
// caller refuses it beyond its reach, as the first answer).
// How deep a touching contact sinks at most: the soft contacts' most at rest (solveContacts()).
double restingSink(const qv_instance& s, double h) { return 3 * s.contactSlop + 2 * norm3(s.frame.gravity) * h * h; }

template <class Query>
bool pressFacing(const qv_instance& s, int v, double margin, double h, double& depth, double normal[3], double own[3],
                 Query query) {
  if (depth > s.contactSlop || !s.model->surfaceMesh) return false;
  s.frame.toWorldDirection(s.model->surfaceMesh->vertexNormals + 3 * v, own);
  double facingDepth, facingNormal[3];
  const double deepest = margin + restingSink(s, h);
  if (dot3(own, normal) <= 0 || !query(facingDepth, facingNormal) || std::fabs(facingDepth) > deepest) return false;
  depth = facingDepth;
  std::memcpy(normal, facingNormal, sizeof facingNormal);
  return true;
}

double distance3(const double a[3], const double b[3]) {
  const double d[3] = {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
  return norm3(d);
}

// Each surface vertex of body i against every collider.
void findColliderContacts(ContactBody* bodies, int i, const qv_collider* colliders, int count, double h,
                          ContactList& list) {
  const qv_instance& s = *bodies[i].instance;
  const bool deforms = s.modeCompliance != nullptr;  // its contacts hold the deformed surface
  const bool swings = norm3(bodies[i].omega) * h > kStraightTurn;
  for (int n = 0; n < s.surfaceCount && count; ++n) {
    const int v = s.surfaceVertices[n];
    double p[3];
    surfacePoint(s, n, deforms, p);
    // A deformed vertex also moves with the deformation, which can outrun the frame many times (a
    // bar's ends flung at the ground while it lies still).
    double flex = 0;
    if (deforms) {
      double w[3];
      s.model->vertexLinear(v, s.v, w, nullptr);
      flex = norm3(w);
    }
    for (int k = 0; k < count; ++k) {
      const qv_collider& col = colliders[k];
      double u[3], depth, normal[3];
      surfaceVelocity(col, p, u);
      const double margin =
          s.contactSlop + 2 * h * std::fmax(relativeSpeed(bodies[i], u) + flex, bodies[i].groupSpeed);
      const double reach = keptReach(list, margin, s.contactSlop);
      if (!colliderDistance(col, p, reach, depth, normal) || depth > reach) continue;
      if (swings) {  // can its arm reach (kStraightTurn)?
        const double arm = distance3(p, s.frame.position);
        double d[3], centre, ignored[3];
        for (int a = 0; a < 3; ++a) d[a] = bodies[i].velocity[a] - u[a];
        // The collider's own spin moves its surface by at most |w| times the arm more than at p.
        const double armReach = arm + 2 * h * (norm3(d) + flex + norm3(col.angular_velocity) * arm) + s.contactSlop;
        if (!colliderDistance(col, s.frame.position, armReach, centre, ignored) || centre > armReach) continue;
      }
      double own[3];
      const bool facing = pressFacing(s, v, margin, h, depth, normal, own, [&](double& d, double nf[3]) {
        return colliderDistance(col, p, margin, d, nf, own);
      });
      if (depth > reach) continue;
      Contact* ct = admit(list, bodies[i], i, -1, k, n, depth);
      if (!ct) continue;
      ct->friction = col.friction, ct->restitution = col.restitution;
      ct->deformedDepth = depth;
      if (!deforms) {
        double deformed[3], ignored[3];
        worldVertex(s, v, true, deformed);
        colliderDistance(col, deformed, INFINITY, ct->deformedDepth, ignored, facing ? own : nullptr);
      }
      for (int a = 0; a < 3; ++a) {
        ct->point[a] = p[a], ct->normal[a] = normal[a], ct->surfaceVelocity[a] = u[a];
        ct->arm[a] = p[a] - s.frame.position[a];
      }
    }
  }
}

// Each surface vertex of body i against body j's rest surface, when their spheres come within reach.
void findBodyContacts(ContactBody* bodies, int i, int j, double h, const ContactMaterial& material,
                      ContactList& list) {
  const qv_instance &a = *bodies[i].instance, &b = *bodies[j].instance;
  if (!b.model->surfaceMesh) return;
  const double margin = bodyMargin(bodies, i, j, h);
  if (!withinMargin(bodies, i, j, margin)) return;
  // A side with soft contacts is its deformed surface: a's vertex where its deformation moved it, b's
  // surface moved where its nearest vertex moved along the normal.
  const bool softA = a.modeCompliance != nullptr, softB = b.modeCompliance != nullptr;
  // Each of a's vertices is a query below, which finds nothing farther than the margin (keptReach()).
  if (boxesApart(a, b, margin)) return;
  // Where either turns fast, the straight paths the margin covers overshoot (kStraightTurn): a's
  // vertex stays within its arm of a's centre, b's rest surface within its radius of b's. Rigid
  // contacts only (a soft side's deformation moves its surface besides).
  const bool swingsA = !softA && !softB && norm3(bodies[i].omega) * h > kStraightTurn;
  const bool swingsB = !softA && !softB && norm3(bodies[j].omega) * h > kStraightTurn;
  const double slop = std::fmax(a.contactSlop, b.contactSlop);
  double travel = 0;  // the frames' straight travel against each other (twice, as the margins)
  {
    double d[3];
    for (int k = 0; k < 3; ++k) d[k] = bodies[i].velocity[k] - bodies[j].velocity[k];
    travel = 2 * h * norm3(d);
  }
  // a's centre's distance to b's rest surface, whose spin moves it by at most |w| times its radius.
  const double lead = travel + 2 * h * norm3(bodies[j].omega) * b.surfaceRadius;
  double centre = INFINITY;
  if (swingsA) {
    double ignored[3];
    if (!bodyDistance(b, a.frame.position, a.surfaceRadius + lead + slop, centre, ignored, nullptr)) centre = INFINITY;
  }
  for (int n = 0; n < a.surfaceCount; ++n) {
    const int v = a.surfaceVertices[n];
    double p[3], depth, normal[3];
    int otherVertex = 0;
    surfacePoint(a, n, softA, p);
    const double reach = keptReach(list, margin, a.contactSlop);
    int nearest = 0, facingNearest = 0;  // the triangles the queries found: hints for the deformed vertex
    if (!bodyDistance(b, p, reach, depth, normal, &otherVertex, nullptr, &nearest) || depth > reach) continue;
    const double arm = distance3(p, a.frame.position);
    // b's rest surface stays within its radius of b's centre; a's vertex closes on that centre by
    // the frames' travel and its own swing, at most twice its arm (the chord).
    if (swingsB && distance3(p, b.frame.position) >
                       b.surfaceRadius + travel + 2 * std::fmin(norm3(bodies[i].omega) * h, 2.0) * arm + slop)
      continue;
    if (swingsA && centre > arm + lead + slop) continue;
    double own[3];
    int facingVertex = 0;
    const bool facing = pressFacing(a, v, margin, h, depth, normal, own, [&](double& d, double nf[3]) {
      return bodyDistance(b, p, margin, d, nf, &facingVertex, own, &facingNearest);
    });
    if (facing) otherVertex = facingVertex;
    const auto moved = [&] {  // b's nearest vertex along the normal
      double u[3], uWorld[3];
      b.model->vertexLinear(otherVertex, b.q, u, nullptr);
      b.frame.toWorldDirection(u, uWorld);
      return dot3(uWorld, normal);
    };
    if (softB) depth -= moved();
    if (depth > reach) continue;
    Contact* ct = admit(list, bodies[i], i, j, -1, n, depth);
    if (!ct) continue;
    ct->otherVertex = otherVertex;
    ct->friction = material.friction, ct->restitution = material.restitution;
    // Reported: the deformed vertex against the other's deformed surface.
    ct->deformedDepth = depth;
    if (!softA) {
      double deformed[3], ignored[3];
      worldVertex(a, v, true, deformed);
      bodyDistance(b, deformed, INFINITY, ct->deformedDepth, ignored, nullptr, facing ? own : nullptr, nullptr,
                   facing ? facingNearest : nearest);
      ct->deformedDepth -= moved();
    } else if (!softB) {
      ct->deformedDepth -= moved();
    }
    for (int k = 0; k < 3; ++k) {
      ct->point[k] = p[k], ct->normal[k] = normal[k];
      ct->arm[k] = p[k] - a.frame.position[k];
      ct->otherArm[k] = p[k] - b.frame.position[k];
    }
  }
}

} // namespace

void deformSurface(qv_instance& s) {
  const qv_model& m = *s.model;
  for (int n = 0; n < s.surfaceCount; ++n) {
    const int v = s.surfaceVertices[n];
    double u[3];
    m.vertexLinear(v, s.q, u, nullptr);
    double* x = s.deformedSurface + 3 * n;
    for (int a = 0; a < 3; ++a) {
      x[a] = m.rest[3 * v + a] - m.rigidBody[a] + u[a];  // as worldVertex() forms it
      s.surfaceLow[a] = n ? std::fmin(s.surfaceLow[a], x[a]) : x[a];
      s.surfaceHigh[a] = n ? std::fmax(s.surfaceHigh[a], x[a]) : x[a];
    }
  }
}

bool boxesApart(const qv_instance& a, const qv_instance& b, double margin) {
  const BvhNode& root = b.model->surfaceMesh->nodes[0];
  double centreA[3], centreB[3], extentA[3], extentB[3], worldA[3], worldB[3], t[3], C[9];
  for (int k = 0; k < 3; ++k) {
    centreA[k] = 0.5 * (a.surfaceLow[k] + a.surfaceHigh[k]), extentA[k] = 0.5 * (a.surfaceHigh[k] - a.surfaceLow[k]);
    centreB[k] = 0.5 * (root.lo[k] + root.hi[k]) - b.model->rigidBody[k], extentB[k] = 0.5 * (root.hi[k] - root.lo[k]);
  }
  a.frame.toWorld(centreA, worldA);
  b.frame.toWorld(centreB, worldB);
  for (int k = 0; k < 3; ++k) worldB[k] -= worldA[k];
  a.frame.toBody(worldB, t);  // b's centre from a's, in a's axes
  const double *Ra = a.frame.rotation, *Rb = b.frame.rotation;
  for (int i = 0; i < 3; ++i)  // C_ij = a's axis i . b's axis j
    for (int j = 0; j < 3; ++j) C[3 * i + j] = std::fabs(Ra[i] * Rb[j] + Ra[3 + i] * Rb[3 + j] + Ra[6 + i] * Rb[6 + j]) + 1e-9;
  // Rounding: relative to the lengths compared and to the positions they were worked out from.
  const double scale = norm3(a.frame.position) + norm3(b.frame.position);
  const auto apart = [&](double distance, double reachA, double reachB) {
    return distance - reachA - reachB > margin + 1e-9 * (distance + reachA + reachB + margin + scale) + 1e-12;
  };
  for (int i = 0; i < 3; ++i)
    if (apart(std::fabs(t[i]), extentA[i], extentB[0] * C[3 * i] + extentB[1] * C[3 * i + 1] + extentB[2] * C[3 * i + 2]))
      return true;
  for (int j = 0; j < 3; ++j) {
    double along = 0, reachA = 0;
    for (int i = 0; i < 3; ++i) {
      along += t[i] * (Ra[i] * Rb[j] + Ra[3 + i] * Rb[3 + j] + Ra[6 + i] * Rb[6 + j]);
      reachA += extentA[i] * C[3 * i + j];
    }
    if (apart(std::fabs(along), reachA, extentB[j])) return true;
  }
  return false;
}

bool validCollider(const qv_collider& c) {
  if (!finiteAll(c.data, 8) || !finiteAll(c.rotation, 3) || !finiteAll(c.velocity, 3) ||
      !finiteAll(c.angular_velocity, 3) || !(c.friction >= 0) || !std::isfinite(c.friction) ||
      !(c.restitution >= 0) || !(c.restitution <= 1))
    return false;
  switch (cEnumValue(c.type)) {
    case QV_COLLIDER_PLANE: return dot3(c.data, c.data) > 0;
    case QV_COLLIDER_SPHERE: return c.data[3] > 0;
    case QV_COLLIDER_BOX: return c.data[3] > 0 && c.data[4] > 0 && c.data[5] > 0;
    case QV_COLLIDER_CAPSULE: return c.data[6] > 0;
    case QV_COLLIDER_MESH: return c.mesh != nullptr;
    default: return false;
  }
}

bool colliderDistance(const qv_collider& c, const double p[3], double reach, double& distance, double normal[3],
                      const double* facing) {
  const double* d = c.data;
  double R[9], local[3], localNormal[3], localFacing[3];
  const bool turned = (c.type == QV_COLLIDER_BOX || c.type == QV_COLLIDER_MESH) && colliderRotation(c, R);
  if (c.type == QV_COLLIDER_BOX || c.type == QV_COLLIDER_MESH) {  // into the collider's own frame: R^T (p - centre)
    const double rel[3] = {p[0] - d[0], p[1] - d[1], p[2] - d[2]};
    for (int a = 0; a < 3; ++a) local[a] = turned ? R[a] * rel[0] + R[3 + a] * rel[1] + R[6 + a] * rel[2] : rel[a];
    if (facing)
      for (int a = 0; a < 3; ++a)
        localFacing[a] = turned ? R[a] * facing[0] + R[3 + a] * facing[1] + R[6 + a] * facing[2] : facing[a];
  }
  switch (c.type) {
    case QV_COLLIDER_PLANE: {  // points with n . x = d
      const double len = norm3(d);
      for (int a = 0; a < 3; ++a) normal[a] = d[a] / len;
      distance = (dot3(d, p) - d[3]) / len;
      return true;
    }
    case QV_COLLIDER_SPHERE:
      distance = away(p, d, normal) - d[3];
      return true;
    case QV_COLLIDER_CAPSULE: {  // segment d[0..2] - d[3..5], radius d[6]
      const double axis[3] = {d[3] - d[0], d[4] - d[1], d[5] - d[2]}, rel[3] = {p[0] - d[0], p[1] - d[1], p[2] - d[2]};
      const double len2 = dot3(axis, axis);
      const double t = len2 > 0 ? std::fmin(1.0, std::fmax(0.0, dot3(rel, axis) / len2)) : 0.0;
      const double closest[3] = {d[0] + t * axis[0], d[1] + t * axis[1], d[2] + t * axis[2]};
      distance = away(p, closest, normal) - d[6];
      return true;
    }
    case QV_COLLIDER_BOX:
      if (!facing) {
        distance = boxDistance(local, d + 3, localNormal);
      } else if (!boxFacingDistance(local, d + 3, localFacing, distance, localNormal)) {
        return false;
      }
      break;
    case QV_COLLIDER_MESH:
      if (!c.mesh || !c.mesh->distance(local, reach, distance, localNormal, nullptr, facing ? localFacing : nullptr)) return false;
      break;
    default: return false;
  }
  for (int a = 0; a < 3; ++a)
    normal[a] = turned ? R[3 * a] * localNormal[0] + R[3 * a + 1] * localNormal[1] + R[3 * a + 2] * localNormal[2] : localNormal[a];
  return true;
}

void takeMomenta(ContactBody* bodies, int count, const qv_collider* colliders, int colliderCount, double h,
                 BroadPhase* broad) {
  for (int i = 0; i < count; ++i) {
    ContactBody& b = bodies[i];
    const RigidFrame& f = b.instance->frame;
    std::memcpy(b.velocity, f.velocity, sizeof b.velocity);
    b.inverseMass = 1.0 / b.instance->model->info.total_mass;
    f.worldOmega(b.omega);
    std::memcpy(b.spin, b.omega, sizeof b.spin);
    f.inverseInertiaMatrix(b.inverseInertia);
  }
  spreadSpeeds(bodies, count, colliders, colliderCount, h, broad);
}

int wakeSleepers(ContactBody* bodies, int count, double h, BroadPhase* broad) {
  for (int i = 0; i < count; ++i) bodies[i].wakes = false;
  for (int i = 0; i < count; ++i)
    if (!bodies[i].instance->asleep || bodies[i].nearMovingCollider) bodies[bodies[i].group].wakes = true;
  // Beyond its group: an awake body's margins grow with its group's speed (a sleeper's never
  // exceed an awake body's, so that side decides).
  const auto pair = [&](int i, int j) {
    if (bodies[i].instance->asleep == bodies[j].instance->asleep) return;
    const int awake = bodies[i].instance->asleep ? j : i, sleeper = awake == i ? j : i;
    if (withinMargin(bodies, awake, sleeper, bodyMargin(bodies, awake, sleeper, h))) bodies[bodies[sleeper].group].wakes = true;
  };
  forEachCandidate(bodies, count, broad, [&](const ContactBody& b) { return contactReach(b, h); }, pair);
  int woken = 0;
  for (int i = 0; i < count; ++i)
    if (bodies[i].instance->asleep && bodies[bodies[i].group].wakes) {
      bodies[i].instance->wake();
      bodies[i].instance->sleepGroup = -1;  // its whole sleep group is in its group, woken with it
      ++woken;
    }
  return woken;
}

namespace {

// Body b's pair with a collider or another body, or null.
ContactPair* pairOf(ContactList& list, const ContactBody& b, int other, int collider) {
  for (int p = b.firstPair; p < b.pairEnd; ++p)
    if (list.pairs[p].other == other && list.pairs[p].collider == collider) return &list.pairs[p];
  return nullptr;
}

// Deeper than a resting contact sinks, and a slop more.
bool deep(const Contact& ct, const qv_instance& s, double h) { return ct.depth < -(restingSink(s, h) + s.contactSlop); }

// A vertex deep inside another body or a collider (spawned there, or pushed in) takes the nearest
// face, and deep inside that is any face: one pair's contacts then push every way at once, which
// no velocities satisfy, so their impulses grew sweep after sweep, loaded q with them and spun the
// frames (a bar spawned through a cube's middle flew off at 84 m/s, spinning at 2900 rad/s). Each
// pair (both directions of a pair of bodies) keeps only the deep contacts that push along its mean
// push, the deep contacts' normals weighted by their depths; where those cancel (a body spawned at
// another's centre), along its shallowest deep contact, the nearest way out. A contact whose pair
// the full table could not hold stays.
void keepConsistentPushes(const ContactBody* bodies, ContactList& list, double h) {
  bool any = false;
  for (int p = 0; p < list.pairCount; ++p) {
    ContactPair& pair = list.pairs[p];
    std::fill(pair.push, pair.push + 3, 0.0);
    pair.weight = 0, pair.exitDepth = -INFINITY;
  }
  for (int k = 0; k < list.count; ++k) {
    const Contact& ct = list.contacts[k];
    ContactPair* pair = deep(ct, *bodies[ct.body].instance, h) ? pairOf(list, bodies[ct.body], ct.other, ct.collider) : nullptr;
    if (!pair) continue;
    for (int a = 0; a < 3; ++a) pair->push[a] -= ct.depth * ct.normal[a];
    pair->weight -= ct.depth;
    if (ct.depth > pair->exitDepth) pair->exitDepth = ct.depth, std::memcpy(pair->exit, ct.normal, sizeof pair->exit);
    any = true;
  }
  if (!any) return;
  int kept = 0;
  for (int k = 0; k < list.count; ++k) {
    const Contact& ct = list.contacts[k];
    const ContactPair* pair = deep(ct, *bodies[ct.body].instance, h) ? pairOf(list, bodies[ct.body], ct.other, ct.collider) : nullptr;
    if (pair) {
      const ContactPair* back = ct.other >= 0 ? pairOf(list, bodies[ct.other], ct.body, -1) : nullptr;
      // The pair's push on this body: its own deep contacts' less the other's on it.
      double push[3];
      for (int a = 0; a < 3; ++a) push[a] = pair->push[a] - (back ? back->push[a] : 0);
      if (norm3(push) <= 1e-6 * (pair->weight + (back ? back->weight : 0))) {
        const bool backExits = back && back->exitDepth > pair->exitDepth;
        for (int a = 0; a < 3; ++a) push[a] = backExits ? -back->exit[a] : pair->exit[a];
      }
      if (!(dot3(push, ct.normal) > 0)) continue;
    }
    list.contacts[kept++] = ct;
  }
  list.count = kept;
}

} // namespace

void solveContacts(ContactBody* bodies, int bodyCount, const qv_collider* colliders, int colliderCount,
                   const ContactMaterial& material, ContactList& list, double h, BroadPhase* broad,
                   const qv_job_runner* jobs) {
  std::swap(list.contacts, list.previous);
  list.previousCount = list.count;
  list.count = 0;
  list.full = false;
  // Each body's candidates in ascending order (as a scan of all would meet them: a full list's
  // choice depends on the order it meets its candidates).
  if (broad) {
    sortByReach(bodies, bodyCount, *broad, [&](const ContactBody& b) { return contactReach(b, h); });
    listOverlaps(*broad);
  }
  const bool rows = broad && broad->rowsValid;
  // Contacts: each surface vertex of the rest shape carried by the frame. Found and solved on the
  // rigid shape: the deformation takes the forces but does not move the contacts (taking its
  // vertices made the loads on q and the contacts chase each other: a resting bar fluttered, bent
  // 1.5 cm, its contacts hopping between its ends and its middle every few steps). Soft contacts
  // take its vertices, and solve its deformation with them (contact.h).
  const auto find = [&] {
    for (int i = 0; i < bodyCount; ++i) {
      if (!list.reducing) bodies[i].firstPair = bodies[i].pairEnd = list.pairCount;
      if (bodies[i].instance->asleep) continue;
      findColliderContacts(bodies, i, colliders, colliderCount, h, list);
      const int* others = rows ? broad->neighbours + broad->rowStart[i] : nullptr;
      const int otherCount = rows ? broad->rowStart[i + 1] - broad->rowStart[i] : bodyCount;
      for (int k = 0; k < otherCount; ++k) {
        const int j = others ? others[k] : k;
        if (j != i && !bodies[j].instance->asleep) findBodyContacts(bodies, i, j, h, material, list);
      }
    }
  };
  for (int i = 0; i < bodyCount; ++i) {
    qv_instance& s = *bodies[i].instance;
    if (!s.asleep && s.deformedSurface) deformSurface(s);
  }
  list.pairCount = list.touching = 0;
  find();
  if (list.touching > list.capacity) {  // again, keeping a spread subset of each pair's
    keepLevels(list);
    list.count = 0;
    list.full = false;
    list.reducing = true;
    find();
    list.reducing = false;
  }
  if (!list.count) return;
  std::sort(list.contacts, list.contacts + list.count, keyBefore);
  keepConsistentPushes(bodies, list, h);

  // The relative velocity at a contact: body's frame less the other's (or the collider's surface),
  // and where the impulses so far move each side's deformation. Friction holds the deformed
  // vertices too: holding the frames only, it loaded q with impulses that did not stop its
  // vertices, and a bar at rest pumped its deformation up (|q| 50x) and jittered.
  const auto relativeVelocity = [&](const Contact& ct, double out[3]) {
    bodyPointVelocity(bodies[ct.body], ct.arm, out);
    double other[3];
    if (ct.other >= 0) {
      bodyPointVelocity(bodies[ct.other], ct.otherArm, other);
    } else {
      std::memcpy(other, ct.surfaceVelocity, sizeof other);
    }
    double giving[3];
    if (ct.rows) {
      modeVelocityAt(*bodies[ct.body].instance, ct.rows, giving);
      for (int a = 0; a < 3; ++a) out[a] += giving[a];
    }
    if (ct.otherRows) {
      modeVelocityAt(*bodies[ct.other].instance, ct.otherRows, giving);
      for (int a = 0; a < 3; ++a) out[a] -= giving[a];
    }
    for (int a = 0; a < 3; ++a) out[a] -= other[a];
  };
  // The mass an impulse along each of the contact's directions meets, and the spin it gives each
  // side per unit (ContactTurns), formed once a solve.
  const auto meetMasses = [&](Contact& ct, ContactTurns& turns) {
    const double* directions[3] = {ct.normal, ct.tangent[0], ct.tangent[1]};
    double inverse[3];
    for (int k = 0; k < 3; ++k) {
      const double* d = directions[k];
      inverse[k] = turnPerImpulse(bodies[ct.body], ct.arm, d, turns.body[k]);
      if (ct.other >= 0) inverse[k] += turnPerImpulse(bodies[ct.other], ct.otherArm, d, turns.other[k]);
      if (ct.rows) inverse[k] += modeGiving(*bodies[ct.body].instance, ct.rows, d);
      if (ct.otherRows) inverse[k] += modeGiving(*bodies[ct.other].instance, ct.otherRows, d);
    }
    ct.normalMass = 1.0 / inverse[0];
    for (int t = 0; t < 2; ++t) ct.tangentMass[t] = 1.0 / inverse[1 + t];
  };
  // The impulse sum_k lambda_k (normal, tangent 0, tangent 1)_k at contact j on the frames and on
  // the deformations where they give way.
  const auto apply = [&](int j, const double lambda[3]) {
    const Contact& ct = list.contacts[j];
    const ContactTurns& turns = list.turns[j];
    double J[3];
    impulseAlong(ct, lambda, J);
    applyImpulse(bodies[ct.body], turns.body, lambda, J, 1);
    if (ct.other >= 0) applyImpulse(bodies[ct.other], turns.other, lambda, J, -1);
    if (ct.rows) pushModes(*bodies[ct.body].instance, ct.rows, J, 1);
    if (ct.otherRows) pushModes(*bodies[ct.other].instance, ct.otherRows, J, -1);
  };
  // A soft side's deformation moves without the contacts as well: predicted once per body that
  // has some (an elastic evaluation each).
  const auto predicted = [&](int body) {
    ContactBody& b = bodies[body];
    if (!b.modesPredicted) b.instance->predictContactModes(), b.modesPredicted = true;
  };
  for (int i = 0; i < bodyCount; ++i) bodies[i].modesPredicted = false;
  for (int j = 0; j < list.count; ++j) {
    Contact& ct = list.contacts[j];
    const qv_instance& s = *bodies[ct.body].instance;
    const double slop = s.contactSlop;
    // Slower approaches than the step's gravity gives rest instead of bouncing.
    const double bounceSpeed = 2 * norm3(s.frame.gravity) * h + 1e-3;
    double vel[3];
    relativeVelocity(ct, vel);
    const double vn = dot3(vel, ct.normal);
    ct.bounce = vn < -bounceSpeed ? -ct.restitution * vn : 0.0;
    // Each side's deformation gives way where its vertex is a contact point of a body stepped
    // implicitly: the contact then holds the deformed surface, not the rigid shape. Not in a
    // bounce: restitution is the frames' (the deformation giving way took up the rebound of an
    // elastic hit between two bars, which then barely exchanged their speeds).
    ct.rows = s.modeCompliance && !ct.bounce ? s.model->contactModes.rowsOf(ct.vertex, s.r) : nullptr;
    if (ct.rows) predicted(ct.body);
    if (ct.other >= 0 && !ct.bounce) {
      const qv_instance& o = *bodies[ct.other].instance;
      ct.otherRows = o.modeCompliance ? o.model->contactModes.rowsOf(ct.otherVertex, o.r) : nullptr;
      if (ct.otherRows) predicted(ct.other);
    }
    // Approach until the surfaces meet, no further; push out what penetrates beyond the slop.
    const double pushOut = 0.2 * (-ct.depth - slop) / h;
    ct.target = ct.depth > slop ? -ct.depth / h : deep(ct, s, h) ? std::fmin(pushOut, kMaxPushOut) : pushOut;
    // Tangents: the sliding direction first (any, when not sliding).
    double t0[3] = {vel[0] - vn * ct.normal[0], vel[1] - vn * ct.normal[1], vel[2] - vn * ct.normal[2]};
    double len = norm3(t0);
    if (len < 1e-12) {
      const double helper[3] = {std::fabs(ct.normal[0]) < 0.9 ? 1.0 : 0.0, std::fabs(ct.normal[0]) < 0.9 ? 0.0 : 1.0, 0};
      cross3(ct.normal, helper, t0);
      len = norm3(t0);
    }
    for (int a = 0; a < 3; ++a) ct.tangent[0][a] = t0[a] / len;
    cross3(ct.normal, ct.tangent[0], ct.tangent[1]);
    meetMasses(ct, list.turns[j]);
    ct.restingImpulse = 4 * ct.normalMass * (norm3(s.frame.gravity) * h + slop / h);
  }
  // Warm start: a contact held since the last step starts from the impulses it ended with (the
  // friction's turned into this step's tangents, within its disc), as if the last solve went on.
  for (int j = 0; j < list.count; ++j) {
    Contact& ct = list.contacts[j];
    const Contact* last = std::lower_bound(list.previous, list.previous + list.previousCount, ct, keyBefore);
    if (last == list.previous + list.previousCount || keyBefore(ct, *last) || ct.bounce > 0) continue;
    double friction[3];
    for (int a = 0; a < 3; ++a)
      friction[a] = last->tangentImpulse[0] * last->tangent[0][a] + last->tangentImpulse[1] * last->tangent[1][a];
    ct.normalImpulse = last->normalImpulse;
    for (int t = 0; t < 2; ++t) ct.tangentImpulse[t] = dot3(friction, ct.tangent[t]);
    const double size = std::hypot(ct.tangentImpulse[0], ct.tangentImpulse[1]), limit = ct.friction * ct.normalImpulse;
    if (size > limit) ct.tangentImpulse[0] *= limit / size, ct.tangentImpulse[1] *= limit / size;
    const double lambda[3] = {ct.normalImpulse, ct.tangentImpulse[0], ct.tangentImpulse[1]};
    apply(j, lambda);
  }
  // Islands: the bodies the contacts join, each swept until its impulses settle (kConverged), an
  // island with a bounce at least until the bounce's sweeps (after kSweeps / 2). Islands share no
  // contact, so each is solved as if alone.
  const auto islandOf = [&](int i) {
    while (bodies[i].island != i) i = bodies[i].island = bodies[bodies[i].island].island;
    return i;
  };
  for (int i = 0; i < bodyCount; ++i) bodies[i].island = i, bodies[i].islandBounces = false;
  for (int j = 0; j < list.count; ++j)
    if (list.contacts[j].other >= 0) {
      const int a = islandOf(list.contacts[j].body), b = islandOf(list.contacts[j].other);
      bodies[std::max(a, b)].island = std::min(a, b);
    }
  for (int i = 0; i < bodyCount; ++i) bodies[i].island = islandOf(i);
  for (int j = 0; j < list.count; ++j) bodies[bodies[list.contacts[j].body].island].islandBounces |= list.contacts[j].bounce > 0;
  // Each island's contacts in the list's order (a counting sort by island), at list.order[first, end)
  // of its root.
  for (int i = 0; i < bodyCount; ++i) bodies[i].islandFirst = bodies[i].islandEnd = 0;
  for (int j = 0; j < list.count; ++j) ++bodies[bodies[list.contacts[j].body].island].islandEnd;
  for (int i = 0, at = 0; i < bodyCount; ++i) {
    const int contacts = bodies[i].islandEnd;
    bodies[i].islandFirst = bodies[i].islandEnd = at;
    at += contacts;
  }
  for (int j = 0; j < list.count; ++j) list.order[bodies[bodies[list.contacts[j].body].island].islandEnd++] = j;
  const auto sweepIsland = [&](ContactBody& island) {
    for (int sweep = 0; sweep < kSweeps; ++sweep) {
      bool moved = false;
      for (int k = island.islandFirst; k < island.islandEnd; ++k) {
        const int j = list.order[k];
        Contact& ct = list.contacts[j];
        const double startNormal = ct.normalImpulse, startTangent[2] = {ct.tangentImpulse[0], ct.tangentImpulse[1]};
        // Restitution once the contact holds: the last sweeps aim at the bounce, as fast away as the
        // approach was times the restitution, where the impulse pushes (speculative contacts would
        // otherwise stop the approach a step early and never bounce).
        if (sweep == kSweeps / 2) {
          ct.stopImpulse = ct.normalImpulse;
          if (ct.normalImpulse > 0 && ct.bounce > 0) ct.target = std::fmax(ct.target, ct.bounce);
        }
        double vel[3];
        relativeVelocity(ct, vel);
        // Normal: accumulated impulse >= 0. Slightly soft (compliance kSoftness / normalMass) up to
        // the impulses resting takes: a resting face shares its weight among its contacts by how deep
        // each is, rather than as the sweep order happens to (which dents a soft object under a few
        // loaded vertices); an impact's impulse beyond that is stiff (softness let 10% of a landing's
        // speed through: 5 mm in a step at 3 m/s).
        const double before = ct.normalImpulse, soft = std::fmin(before, ct.restingImpulse);
        const double stiff = ct.normalImpulse > ct.restingImpulse ? 1.0 : 1 + kSoftness;
        ct.normalImpulse = std::fmax(0.0, before + (ct.target - dot3(vel, ct.normal) - kSoftness * soft / ct.normalMass) /
                                                   (stiff / ct.normalMass));
        const double push[3] = {ct.normalImpulse - before, 0, 0};
        apply(j, push);
        // Friction: the accumulated tangent impulse within the disc of radius mu * normal impulse.
        relativeVelocity(ct, vel);
        const double limit = ct.friction * ct.normalImpulse;
        const double old[2] = {ct.tangentImpulse[0], ct.tangentImpulse[1]};
        double next[2];
        for (int t = 0; t < 2; ++t) next[t] = old[t] - ct.tangentMass[t] * dot3(vel, ct.tangent[t]);
        const double size = std::sqrt(next[0] * next[0] + next[1] * next[1]);
        if (size > limit) next[0] *= limit / size, next[1] *= limit / size;
        const double rub[3] = {0, next[0] - old[0], next[1] - old[1]};
        ct.tangentImpulse[0] = next[0], ct.tangentImpulse[1] = next[1];
        apply(j, rub);
        const double change = std::fabs(ct.normalImpulse - startNormal) + std::fabs(next[0] - startTangent[0]) +
                              std::fabs(next[1] - startTangent[1]);
        moved |= change > kConverged * ct.restingImpulse;
      }
      if (!moved && (!island.islandBounces || sweep > kSweeps / 2)) return;
    }
  };
  // Islands touch no body in common, so they are swept in the caller's jobs (contiguous shares of
  // the contacts, whole islands each) with the same bits; one island (a pile) on the calling thread.
  const auto heldIsland = [&](int i) { return bodies[i].island == i && bodies[i].islandEnd > bodies[i].islandFirst; };
  int islands = 0;
  for (int i = 0; i < bodyCount && islands < 2; ++i) islands += heldIsland(i);
  const int jobCount = jobs && islands > 1 ? jobs->count : 1;
  const auto sweepJob = [&](int job) {
    for (int i = 0; i < bodyCount; ++i)
      if (heldIsland(i) && static_cast<long long>(bodies[i].islandFirst) * jobCount / list.count == job) sweepIsland(bodies[i]);
  };
  runJobs(jobs, jobCount, sweepJob);
  for (int i = 0; i < bodyCount; ++i) {
    std::memcpy(bodies[i].instance->frame.velocity, bodies[i].velocity, sizeof bodies[i].velocity);
    if (bodies[i].modesPredicted) bodies[i].instance->softContact = true;
  }
  // Each contact's whole impulse adds its angular momenta, a x J (the solve stepped the spin alone),
  // and over the step loads the deformations where it acts, less the bounce: the restitution
  // already returns that energy to the frames, and loading q with it too would make energy.
  for (int j = 0; j < list.count; ++j) {
    const Contact& ct = list.contacts[j];
    const double whole[3] = {ct.normalImpulse, ct.tangentImpulse[0], ct.tangentImpulse[1]};
    const double loaded[3] = {ct.bounce > 0 ? std::fmin(ct.normalImpulse, ct.stopImpulse) : ct.normalImpulse,
                              ct.tangentImpulse[0], ct.tangentImpulse[1]};
    double J[3], world[3];
    impulseAlong(ct, whole, J);
    impulseAlong(ct, loaded, world);
    for (int a = 0; a < 3; ++a) world[a] /= h;
    const auto act = [&](int body, const double arm[3], int vertex, double sign) {
      qv_instance& s = *bodies[body].instance;
      double turn[3], force[3], local[3];
      cross3(arm, J, turn);
      for (int a = 0; a < 3; ++a) s.frame.angularMomentum[a] += sign * turn[a], force[a] = sign * world[a];
      s.frame.toBody(force, local);
      s.loads.addVertexForce(*s.model, s.config.elasticity, s.q, vertex, local);
      s.touching = true;
    };
    act(ct.body, ct.arm, ct.vertex, 1);
    if (ct.other >= 0) act(ct.other, ct.otherArm, ct.otherVertex, -1);
  }
}

} // namespace quiver::rt
