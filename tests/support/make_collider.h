#pragma once
// A qv_collider from its type, data, friction and restitution; static, unturned, no mesh.
#include <algorithm>
#include <array>

#include "quiver/quiver.h"

namespace quiver::test {

inline qv_collider makeCollider(qv_collider_type type, std::array<double, 8> data, double friction = 0,
                                double restitution = 0) {
  qv_collider c{};
  c.type = type;
  std::copy(data.begin(), data.end(), c.data);
  c.friction = friction;
  c.restitution = restitution;
  return c;
}

} // namespace quiver::test
