#pragma once
// qv_world: flying instances that touch each other and the world's colliders (contact.h). One
// block from the caller's allocator, sized by its config; the step allocates nothing.
#include "contact.h"

struct qv_world {
  qv_allocator allocator;
  qv_world_config config;
  qv_instance** instances = nullptr;  // the caller's, in qv_world_add's order
  int count = 0;
  quiver::rt::ContactBody* bodies = nullptr;
  quiver::rt::ContactList contacts;
  const qv_collider* colliders = nullptr;  // the caller's (qv_world_set_colliders)
  int colliderCount = 0;

  // Each instance's frame forces, one contact solve over all, then each move and deformation.
  int step();
};

namespace quiver::rt {

bool validWorldConfig(const qv_world_config& config);
void defaultWorldConfig(qv_world_config& config);
qv_world* createWorld(const qv_world_config& config, const qv_allocator& allocator);
void destroyWorld(qv_world* world);

} // namespace quiver::rt
