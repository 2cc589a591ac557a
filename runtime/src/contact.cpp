#include "contact.h"

#include <cmath>

namespace quiver::rt {

namespace {

constexpr double kSoftness = 0.1;

double dot3(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

void cross3(const double a[3], const double b[3], double out[3]) {
  out[0] = a[1] * b[2] - a[2] * b[1];
  out[1] = a[2] * b[0] - a[0] * b[2];
  out[2] = a[0] * b[1] - a[1] * b[0];
}

bool finiteAll(const double* v, int n) {
  for (int i = 0; i < n; ++i)
    if (!std::isfinite(v[i])) return false;
  return true;
}

// Distance from p to c along d (|d| > 0), normal d / |d|; `fallback` where p is at c.
double away(const double p[3], const double c[3], double normal[3]) {
  const double d[3] = {p[0] - c[0], p[1] - c[1], p[2] - c[2]};
  const double len = std::sqrt(dot3(d, d));
  for (int a = 0; a < 3; ++a) normal[a] = len > 0 ? d[a] / len : (a == 2 ? 1.0 : 0.0);
  return len;
}

// 1 / (1/m + n . ((I^-1 (a x n)) x a)): the mass the impulse along n at arm a meets.
double effectiveMass(const RigidFrame& f, double mass, const double a[3], const double n[3]) {
  double an[3], ian[3], back[3];
  cross3(a, n, an);
  f.inverseInertia(an, ian);
  cross3(ian, a, back);
  return 1.0 / (1.0 / mass + dot3(n, back));
}

} // namespace

bool validCollider(const qv_collider& c) {
  if (!finiteAll(c.data, 8) || !(c.friction >= 0) || !std::isfinite(c.friction) || !(c.restitution >= 0) ||
      !(c.restitution <= 1))
    return false;
  switch (c.type) {
    case QV_COLLIDER_PLANE: return dot3(c.data, c.data) > 0;
    case QV_COLLIDER_SPHERE: return c.data[3] > 0;
    case QV_COLLIDER_BOX: return c.data[3] > 0 && c.data[4] > 0 && c.data[5] > 0;
    case QV_COLLIDER_CAPSULE: return c.data[6] > 0;
    default: return false;
  }
}

bool colliderDistance(const qv_collider& c, const double p[3], double& distance, double normal[3]) {
  const double* d = c.data;
  switch (c.type) {
    case QV_COLLIDER_PLANE: {  // points with n . x = d
      const double len = std::sqrt(dot3(d, d));
      for (int a = 0; a < 3; ++a) normal[a] = d[a] / len;
      distance = (dot3(d, p) - d[3]) / len;
      return true;
    }
    case QV_COLLIDER_SPHERE:
      distance = away(p, d, normal) - d[3];
      return true;
    case QV_COLLIDER_BOX: {  // axis-aligned: centre d[0..2], half extents d[3..5]
      double q[3], outside = 0, inside = -INFINITY;
      int deepest = 0;
      for (int a = 0; a < 3; ++a) {
        q[a] = std::fabs(p[a] - d[a]) - d[3 + a];
        outside += q[a] > 0 ? q[a] * q[a] : 0;
        if (q[a] > inside) inside = q[a], deepest = a;
      }
      if (outside > 0) {
        distance = std::sqrt(outside);
        for (int a = 0; a < 3; ++a) normal[a] = (q[a] > 0 ? q[a] : 0) * (p[a] >= d[a] ? 1 : -1) / distance;
      } else {
        distance = inside;
        for (int a = 0; a < 3; ++a) normal[a] = a == deepest ? (p[a] >= d[a] ? 1 : -1) : 0;
      }
      return true;
    }
    case QV_COLLIDER_CAPSULE: {  // segment d[0..2] - d[3..5], radius d[6]
      const double axis[3] = {d[3] - d[0], d[4] - d[1], d[5] - d[2]}, rel[3] = {p[0] - d[0], p[1] - d[1], p[2] - d[2]};
      const double len2 = dot3(axis, axis);
      const double t = len2 > 0 ? std::fmin(1.0, std::fmax(0.0, dot3(rel, axis) / len2)) : 0.0;
      const double closest[3] = {d[0] + t * axis[0], d[1] + t * axis[1], d[2] + t * axis[2]};
      distance = away(p, closest, normal) - d[6];
      return true;
    }
    default: return false;
  }
}

void solveContacts(qv_instance& s, double h) {
  s.contactCount = 0;
  if (!s.colliderCount) return;
  RigidFrame& f = s.frame;
  const qv_model& m = *s.model;
  const double mass = m.info.total_mass;
  const double* c = m.rigidBody;
  double omega[3];
  f.worldOmega(omega);
  // How fast the frame can carry a vertex: its reach within the step, plus the slop.
  const double speed = std::sqrt(dot3(f.velocity, f.velocity)) + std::sqrt(dot3(omega, omega)) * s.surfaceRadius;
  const double slop = s.contactSlop, margin = slop + 2 * h * speed;
  const double g = std::sqrt(dot3(f.gravity, f.gravity));
  const double bounceSpeed = 2 * g * h + 1e-3;  // slower approaches rest instead of bouncing

  // Contacts: each surface vertex of the rest shape carried by the frame against each collider, the
  // deepest kept when there are too many. Found and solved on the rigid shape: the deformation takes
  // the forces but does not move the contacts (taking its vertices made the loads on q and the
  // contacts chase each other: a resting bar fluttered, bent 1.5 cm, its contacts hopping between
  // its ends and its middle every few steps).
  for (int i = 0; i < s.surfaceCount; ++i) {
    const int v = s.surfaceVertices[i];
    double body[3], p[3];
    for (int a = 0; a < 3; ++a) body[a] = m.rest[3 * v + a] - c[a];
    f.toWorld(body, p);
    for (int k = 0; k < s.colliderCount; ++k) {
      double depth, normal[3];
      if (!colliderDistance(s.colliders[k], p, depth, normal) || depth > margin) continue;
      int slot = s.contactCount;
      if (s.contactCount == s.config.max_contacts) {  // full: replace the shallowest if this is deeper
        slot = 0;
        for (int j = 1; j < s.contactCount; ++j)
          if (s.contacts[j].depth > s.contacts[slot].depth) slot = j;
        if (s.contacts[slot].depth <= depth) continue;
      } else {
        ++s.contactCount;
      }
      Contact& ct = s.contacts[slot];
      ct = Contact{};
      ct.vertex = v;
      ct.collider = k;
      ct.depth = depth;
      // What the caller sees: the deformed vertex's own distance (the deformation adds to the frame's).
      double u[3], deformed[3], world[3], n[3];
      m.vertexLinear(v, s.q, u, nullptr);
      for (int a = 0; a < 3; ++a) deformed[a] = body[a] + u[a];
      f.toWorld(deformed, world);
      colliderDistance(s.colliders[k], world, ct.deformedDepth, n);
      for (int a = 0; a < 3; ++a) {
        ct.point[a] = p[a];
        ct.normal[a] = normal[a];
        ct.arm[a] = p[a] - f.position[a];
      }
    }
  }
  if (!s.contactCount) return;

  // Velocities: the frame's, and each contact point's including the deformation's own.
  double v[3] = {f.velocity[0], f.velocity[1], f.velocity[2]};
  double L[3] = {f.angularMomentum[0], f.angularMomentum[1], f.angularMomentum[2]};
  // The frame's velocity at a contact: v + omega x arm, omega from the current L. (The deformation's
  // own velocity is left out: the frame's impulses cannot change it, and chasing it pumps energy.)
  const auto pointVelocity = [&](const Contact& ct, double out[3]) {
    double w[3], wa[3], dw[3];
    const double dL[3] = {L[0] - f.angularMomentum[0], L[1] - f.angularMomentum[1], L[2] - f.angularMomentum[2]};
    f.inverseInertia(dL, dw);
    for (int a = 0; a < 3; ++a) w[a] = omega[a] + dw[a];
    cross3(w, ct.arm, wa);
    for (int a = 0; a < 3; ++a) out[a] = v[a] + wa[a];
  };
  for (int j = 0; j < s.contactCount; ++j) {
    Contact& ct = s.contacts[j];
    const qv_collider& col = s.colliders[ct.collider];
    double vel[3];
    pointVelocity(ct, vel);
    const double vn = dot3(vel, ct.normal);
    // Approach until the surfaces meet, no further; push out what penetrates beyond the slop.
    ct.target = ct.depth > slop ? -ct.depth / h : 0.2 * (-ct.depth - slop) / h;
    ct.bounce = vn < -bounceSpeed ? -col.restitution * vn : 0.0;
    ct.normalMass = effectiveMass(f, mass, ct.arm, ct.normal);
    // Tangents: the sliding direction first (any, when not sliding).
    double t0[3] = {vel[0] - vn * ct.normal[0], vel[1] - vn * ct.normal[1], vel[2] - vn * ct.normal[2]};
    double len = std::sqrt(dot3(t0, t0));
    if (len < 1e-12) {
      const double helper[3] = {std::fabs(ct.normal[0]) < 0.9 ? 1.0 : 0.0, std::fabs(ct.normal[0]) < 0.9 ? 0.0 : 1.0, 0};
      cross3(ct.normal, helper, t0);
      len = std::sqrt(dot3(t0, t0));
    }
    for (int a = 0; a < 3; ++a) ct.tangent[0][a] = t0[a] / len;
    cross3(ct.normal, ct.tangent[0], ct.tangent[1]);
    for (int t = 0; t < 2; ++t) ct.tangentMass[t] = effectiveMass(f, mass, ct.arm, ct.tangent[t]);
  }
  const auto apply = [&](const Contact& ct, const double impulse[3]) {
    double aj[3];
    cross3(ct.arm, impulse, aj);
    for (int a = 0; a < 3; ++a) {
      v[a] += impulse[a] / mass;
      L[a] += aj[a];
    }
  };
  for (int iteration = 0; iteration < 24; ++iteration)
    for (int j = 0; j < s.contactCount; ++j) {
      Contact& ct = s.contacts[j];
      // Restitution once the contact holds: the last iterations aim at the bounce, as fast away as the
      // approach was times the restitution, where the impulse pushes (speculative contacts would
      // otherwise stop the approach a step early and never bounce).
      if (iteration == 12) {
        ct.stopImpulse = ct.normalImpulse;
        if (ct.normalImpulse > 0 && ct.bounce > 0) ct.target = std::fmax(ct.target, ct.bounce);
      }
      double vel[3];
      pointVelocity(ct, vel);
      // Normal: accumulated impulse >= 0.
      const double before = ct.normalImpulse;
      // Slightly soft (compliance kSoftness / normalMass): a resting face shares its weight among its
      // contacts by how deep each is, rather than as the iteration order happens to (which dents a
      // soft object under a few loaded vertices).
      ct.normalImpulse = std::fmax(0.0, before + (ct.target - dot3(vel, ct.normal) - kSoftness * before / ct.normalMass) /
                                                 ((1 + kSoftness) / ct.normalMass));
      double J[3];
      for (int a = 0; a < 3; ++a) J[a] = (ct.normalImpulse - before) * ct.normal[a];
      apply(ct, J);
      // Friction: the accumulated tangent impulse within the disc of radius mu * normal impulse.
      pointVelocity(ct, vel);
      const double mu = s.colliders[ct.collider].friction, limit = mu * ct.normalImpulse;
      double old[2] = {ct.tangentImpulse[0], ct.tangentImpulse[1]}, next[2];
      for (int t = 0; t < 2; ++t) next[t] = old[t] - ct.tangentMass[t] * dot3(vel, ct.tangent[t]);
      const double size = std::sqrt(next[0] * next[0] + next[1] * next[1]);
      if (size > limit) next[0] *= limit / size, next[1] *= limit / size;
      for (int a = 0; a < 3; ++a)
        J[a] = (next[0] - old[0]) * ct.tangent[0][a] + (next[1] - old[1]) * ct.tangent[1][a];
      ct.tangentImpulse[0] = next[0], ct.tangentImpulse[1] = next[1];
      apply(ct, J);
    }
  for (int a = 0; a < 3; ++a) {
    f.velocity[a] = v[a];
    f.angularMomentum[a] = L[a];
  }
  // The same impulses over the step load the deformation where they act, less the bounce: the
  // restitution already returns that energy to the frame, and loading q with it too would make energy.
  for (int j = 0; j < s.contactCount; ++j) {
    const Contact& ct = s.contacts[j];
    const double normal = ct.bounce > 0 ? std::fmin(ct.normalImpulse, ct.stopImpulse) : ct.normalImpulse;
    double world[3], body[3];
    for (int a = 0; a < 3; ++a)
      world[a] = (normal * ct.normal[a] + ct.tangentImpulse[0] * ct.tangent[0][a] +
                  ct.tangentImpulse[1] * ct.tangent[1][a]) / h;
    f.toBody(world, body);
    s.loads.addVertexForce(m, s.config.elasticity, s.q, ct.vertex, body);
  }
}

} // namespace quiver::rt
