#include "contact_list.h"

#include <algorithm>
#include <cmath>

#include "instance.h"

namespace quiver::rt {

namespace {

Contact recordOf(const double* in) {
  Contact c;
  c.body = static_cast<int>(in[0]);
  c.other = static_cast<int>(in[1]);
  c.collider = static_cast<int>(in[2]);
  c.vertex = static_cast<int>(in[3]);
  std::copy(in + 4, in + 7, c.point);
  std::copy(in + 7, in + 10, c.normal);
  c.deformedDepth = in[10];
  c.normalImpulse = in[11];
  std::copy(in + 12, in + 14, c.tangentImpulse);
  std::copy(in + 14, in + 17, c.tangent[0]);
  std::copy(in + 17, in + 20, c.tangent[1]);
  return c;
}

} // namespace

size_t saveContacts(const ContactList& list, double* out) {
  out[0] = list.count;
  double* o = out + 1;
  for (int j = 0; j < list.count; ++j, o += kContactRecord) {
    const Contact& c = list.contacts[j];
    o[0] = c.body, o[1] = c.other, o[2] = c.collider, o[3] = c.vertex;
    std::copy(c.point, c.point + 3, o + 4);
    std::copy(c.normal, c.normal + 3, o + 7);
    o[10] = c.deformedDepth;
    o[11] = c.normalImpulse;
    std::copy(c.tangentImpulse, c.tangentImpulse + 2, o + 12);
    std::copy(c.tangent[0], c.tangent[0] + 3, o + 14);
    std::copy(c.tangent[1], c.tangent[1] + 3, o + 17);
  }
  return 1 + kContactRecord * static_cast<size_t>(list.count);
}

// Whether v[0, 3) has length 1 (to rounding, as the solve leaves normals and tangents).
bool unit(const double* v) { return std::fabs(v[0] * v[0] + v[1] * v[1] + v[2] * v[2] - 1) <= 1e-9; }

size_t validContacts(const double* in, size_t available, const ContactList& list, const qv_instance* const* bodies,
                     int bodyCount, int colliderCount) {
  if (available < 1) return 0;
  const int count = indexIn(in[0], 0, list.capacity + 1);
  if (count < 0 || available - 1 < kContactRecord * static_cast<size_t>(count)) return 0;
  Contact last;
  for (int j = 0; j < count; ++j) {
    const double* r = in + 1 + kContactRecord * static_cast<size_t>(j);
    if (!std::all_of(r, r + kContactRecord, [](double x) { return std::isfinite(x); }) || !(r[11] >= 0)) return 0;
    if (!unit(r + 7) || !unit(r + 14) || !unit(r + 17)) return 0;
    const int body = indexIn(r[0], 0, bodyCount), other = indexIn(r[1], -1, bodyCount);
    const int collider = indexIn(r[2], -1, colliderCount);
    if (body < 0 || other < -1 || other == body || (other >= 0) != (collider == -1) || collider < -1) return 0;
    if (indexIn(r[3], 0, bodies[body]->model->info.vertex_count) < 0) return 0;
    const Contact c = recordOf(r);
    if (j > 0 && !keyBefore(last, c)) return 0;  // the warm start looks them up in this order
    last = c;
  }
  return 1 + kContactRecord * static_cast<size_t>(count);
}

void restoreContacts(ContactList& list, const double* in) {
  list.clear();
  list.count = static_cast<int>(in[0]);
  for (int j = 0; j < list.count; ++j) list.contacts[j] = recordOf(in + 1 + kContactRecord * static_cast<size_t>(j));
}

} // namespace quiver::rt
