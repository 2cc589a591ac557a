#include "world.h"

#include <cmath>
#include <new>

#include "block_carver.h"

namespace quiver::rt {

namespace {

// Measures (block null) or places the world's arrays; returns the block's size.
size_t layOut(const qv_world_config& config, char* block, qv_world** world) {
  BlockCarver c(block);
  qv_world* w = c.take<qv_world>(1);
  qv_instance** instances = c.take<qv_instance*>(static_cast<size_t>(config.max_instances));
  ContactBody* bodies = c.take<ContactBody>(static_cast<size_t>(config.max_instances));
  Contact* contacts = c.take<Contact>(static_cast<size_t>(config.max_contacts));
  Contact* previous = c.take<Contact>(static_cast<size_t>(config.max_contacts));
  ContactPair* pairs = c.take<ContactPair>(static_cast<size_t>(config.max_contacts));
  if (block) {
    w = new (w) qv_world{};
    w->config = config;
    w->instances = instances;
    w->bodies = new (bodies) ContactBody[config.max_instances];
    w->contacts.contacts = contacts;
    w->contacts.previous = previous;
    w->contacts.pairs = pairs;
    w->contacts.capacity = config.max_contacts;
    *world = w;
  }
  return c.size();
}

} // namespace

bool validWorldConfig(const qv_world_config& c) {
  return c.max_instances >= 1 && c.max_instances <= 65536 && c.max_contacts >= 0 && c.max_contacts <= (1 << 20) &&
         c.friction >= 0 && std::isfinite(c.friction) && c.restitution >= 0 && c.restitution <= 1;
}

void defaultWorldConfig(qv_world_config& config) {
  config.max_instances = 64;
  config.max_contacts = 4096;
  config.friction = 0.5;
  config.restitution = 0;
}

qv_world* createWorld(const qv_world_config& config, const qv_allocator& allocator) {
  const size_t bytes = layOut(config, nullptr, nullptr);
  char* block = static_cast<char*>(allocator.allocate(bytes, 64, allocator.user));
  if (!block) return nullptr;
  qv_world* world = nullptr;
  layOut(config, block, &world);
  world->allocator = allocator;
  return world;
}

void destroyWorld(qv_world* world) {
  const qv_allocator allocator = world->allocator;
  world->~qv_world();
  allocator.release(world, allocator.user);
}

} // namespace quiver::rt

int qv_world::step() {
  for (int i = 0; i < count; ++i) {
    instances[i]->beginStep();
    instances[i]->contacts.clear();
    bodies[i].instance = instances[i];
  }
  const quiver::rt::ContactMaterial between{config.friction, config.restitution};
  if (count) quiver::rt::solveContacts(bodies, count, colliders, colliderCount, between, contacts, instances[0]->config.time_step);
  int resets = 0;
  for (int i = 0; i < count; ++i) resets += instances[i]->finishStep() == QV_STEP_RESET;
  return resets;
}
