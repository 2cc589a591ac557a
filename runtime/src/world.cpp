#include "world.h"

#include <cmath>
#include <cstring>
#include <new>

#include "block_carver.h"
#include "elasticity.h"
#include "jobs.h"

namespace quiver::rt {

namespace {

// How fast an instance still moves: its frame's surface (the fastest spin at its farthest vertex)
// and its deformation's RMS speed over the step, |q - startQ| / (h sqrt(m)) (as |q'|^2 / 2 is its
// kinetic energy). Not |q'| / sqrt(m): the implicit steps leave stiff modes' velocities ringing
// from step to step, undamped, while q hardly moves (a bar vibrating in space kept 3 cm/s after 10 s).
double stillSpeed(const qv_instance& s, double h) {
  double omega[3], dq2 = 0;
  s.frame.inverseInertia(s.frame.angularMomentum, omega);
  for (int i = 0; i < s.r; ++i) dq2 += (s.q[i] - s.startQ[i]) * (s.q[i] - s.startQ[i]);
  return std::hypot(s.frame.velocity[0], s.frame.velocity[1], s.frame.velocity[2]) +
         std::hypot(omega[0], omega[1], omega[2]) * s.surfaceRadius + std::sqrt(dq2 / s.model->info.total_mass) / h;
}

// At rest where it is, in `group`: its pose and deformation kept, its velocities and acceleration
// zero, and no spin change or lost energy for the next step to make up when it wakes.
void fallAsleep(qv_instance& s, int group) {
  s.asleep = true;
  s.sleepGroup = group;
  std::memset(s.v, 0, sizeof(double) * s.r);
  std::memset(s.a, 0, sizeof(double) * s.r);
  s.energySlack = 0;
  // A fixed Newton step's account too (integrators/fixed_newton.h): none left to make up.
  if (s.keepsEnergyAccount()) s.openEnergyAccount(elasticEnergy(*s.model, s.config.elasticity, s.q, s.work.polynomialScratch));
  RigidFrame& f = s.frame;
  std::memset(f.velocity, 0, sizeof f.velocity);
  std::memset(f.angularMomentum, 0, sizeof f.angularMomentum);
  f.refresh(*s.model, s.q, s.v);
  f.turnCredit = 0;
}

// Measures (block null) or places the world's arrays; returns the block's size.
size_t layOut(const qv_world_config& config, char* block, qv_world** world) {
  BlockCarver c(block);
  qv_world* w = c.take<qv_world>(1);
  qv_instance** instances = c.take<qv_instance*>(static_cast<size_t>(config.max_instances));
  ContactBody* bodies = c.take<ContactBody>(static_cast<size_t>(config.max_instances));
  WorldSlot* slots = c.take<WorldSlot>(static_cast<size_t>(config.max_instances));
  BroadPhase broad;
  broad.carve(c, config.max_instances);
  Contact* contacts = c.take<Contact>(static_cast<size_t>(config.max_contacts));
  Contact* previous = c.take<Contact>(static_cast<size_t>(config.max_contacts));
  ContactTurns* turns = c.take<ContactTurns>(static_cast<size_t>(config.max_contacts));
  int* order = c.take<int>(static_cast<size_t>(config.max_contacts));
  ContactPair* pairs = c.take<ContactPair>(static_cast<size_t>(config.max_contacts));
  if (block) {
    w = new (w) qv_world{};
    w->config = config;
    w->instances = instances;
    w->bodies = new (bodies) ContactBody[config.max_instances];
    w->slots = new (slots) WorldSlot[config.max_instances];
    w->broad = broad;
    w->contacts.contacts = contacts;
    w->contacts.previous = previous;
    w->contacts.turns = turns;
    w->contacts.order = order;
    w->contacts.pairs = pairs;
    w->contacts.capacity = config.max_contacts;
    *world = w;
  }
  return c.size();
}

} // namespace

bool validWorldConfig(const qv_world_config& c) {
  return c.max_instances >= 1 && c.max_instances <= 65536 && c.max_contacts >= 0 && c.max_contacts <= (1 << 20) &&
         c.friction >= 0 && std::isfinite(c.friction) && c.restitution >= 0 && c.restitution <= 1 &&
         c.sleep_speed >= 0 && std::isfinite(c.sleep_speed) && c.sleep_time >= 0 && std::isfinite(c.sleep_time);
}

void defaultWorldConfig(qv_world_config& config) {
  config.max_instances = 64;
  config.max_contacts = 4096;
  config.friction = 0.5;
  config.restitution = 0;
  config.sleep_speed = 0.02;
  config.sleep_time = 0.5;
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

void qv_world::forEachInstance(void (*part)(qv_world&, int)) {
  const int jobCount = jobs ? jobs->count : 1;
  quiver::rt::runJobs(jobs, jobCount, [&](int job) {
    const int first = static_cast<int>(static_cast<long long>(count) * job / jobCount);
    const int end = static_cast<int>(static_cast<long long>(count) * (job + 1) / jobCount);
    for (int i = first; i < end; ++i) part(*this, i);
  });
}

int qv_world::step() {
  if (!count) return 0;
  const double h = instances[0]->config.time_step;
  for (int i = 0; i < count; ++i) bodies[i].instance = instances[i];
  wakeSleptWith();
  // Each instance's own parts of the step (its frame's forces; after the solve its move and
  // deformation) touch that instance alone, so they run in the caller's jobs, with the same bits (as
  // do the solve's islands).
  forEachInstance([](qv_world& w, int i) {
    if (!w.instances[i]->asleep) w.begin(i);
  });
  int awake = 0;
  for (int i = 0; i < count; ++i) awake += !instances[i]->asleep;
  quiver::rt::takeMomenta(bodies, count, colliders, colliderCount, h, &broad);
  // Woken bodies start their step and may reach other sleepers in it.
  while (awake < count && quiver::rt::wakeSleepers(bodies, count, h, &broad)) {
    for (int i = 0; i < count; ++i)
      if (!instances[i]->asleep && !slots[i].begun) begin(i), ++awake;
    quiver::rt::takeMomenta(bodies, count, colliders, colliderCount, h, &broad);
  }
  const quiver::rt::ContactMaterial between{config.friction, config.restitution};
  if (awake) {
    quiver::rt::solveContacts(bodies, count, colliders, colliderCount, between, contacts, h, &broad, jobs);
  } else {
    contacts.clear();
  }
  forEachInstance([](qv_world& w, int i) {
    w.slots[i].reset = !w.instances[i]->asleep && w.instances[i]->finishStep() == QV_STEP_RESET;
  });
  int resets = 0;
  for (int i = 0; i < count; ++i) resets += slots[i].reset;
  settle(h);
  return resets;
}

size_t qv_world::snapshotSize() const {
  size_t doubles = 2 + quiver::rt::kContactRecord * static_cast<size_t>(contacts.capacity);
  for (int i = 0; i < count; ++i) doubles += 3 + instances[i]->stateSize();
  return sizeof(double) * doubles;
}

size_t qv_world::saveSnapshot(double* out) const {
  double* o = out;
  *o++ = count;
  for (int i = 0; i < count; ++i) {
    const qv_instance& s = *instances[i];
    o[0] = s.asleep ? 1 : 0, o[1] = s.stillTime, o[2] = s.sleepGroup;
    s.saveState(o + 3);
    o += 3 + s.stateSize();
  }
  o += quiver::rt::saveContacts(contacts, o);
  return sizeof(double) * static_cast<size_t>(o - out);
}

bool qv_world::restoreSnapshot(const double* in, size_t bytes) {
  // All checked before anything changes: the same number of instances, each one's sleep and state
  // valid for it, and contacts between them.
  const size_t available = bytes / sizeof(double);
  if (bytes > snapshotSize() || available < 1 || in[0] != count) return false;
  size_t at = 1;
  for (int i = 0; i < count; ++i) {
    const qv_instance& s = *instances[i];
    if (available < at + 3 + s.stateSize()) return false;
    const double* sleep = in + at;
    if ((sleep[0] != 0 && sleep[0] != 1) || !(sleep[1] >= 0 && sleep[1] < INFINITY) ||
        quiver::rt::indexIn(sleep[2], -1, count) < -1 || !s.validState(sleep + 3))
      return false;
    at += 3 + s.stateSize();
  }
  if (!quiver::rt::validContacts(in + at, available - at, contacts, instances, count, colliderCount)) return false;
  at = 1;
  for (int i = 0; i < count; ++i) {
    qv_instance& s = *instances[i];
    s.asleep = in[at] != 0, s.stillTime = in[at + 1], s.sleepGroup = static_cast<int>(in[at + 2]);
    s.restoreState(in + at + 3);
    s.contacts.clear();  // a world step clears them
    at += 3 + s.stateSize();
  }
  quiver::rt::restoreContacts(contacts, in + at);
  return true;
}

void qv_world::remove(int i) {
  qv_instance& gone = *instances[i];
  // What slept with it wakes (a stack whose lowest is taken away must fall), whether it still sleeps
  // or the caller woke it since the last step (wakeSleptWith() would have woken them at the next).
  // Then no sleeper keeps its index as a group's id (a group's id is its root's index when it fell
  // asleep, and the root is in the group), so the ids above its index stay distinct one lower.
  for (int j = 0; j < count; ++j) {
    qv_instance& s = *instances[j];
    if (j == i || s.sleepGroup < 0) continue;
    if (gone.sleepGroup >= 0 && s.sleepGroup == gone.sleepGroup) {
      s.wake(), s.sleepGroup = -1;
    } else if (s.sleepGroup > i) {
      --s.sleepGroup;
    }
  }
  gone.wake(), gone.sleepGroup = -1;
  gone.contacts.clear();  // stepped alone from here, from no contacts
  for (int j = i + 1; j < count; ++j) instances[j - 1] = instances[j];
  --count;
  // The last step's contacts keep their order (by body, then other) with the indices above i one lower.
  int kept = 0;
  for (int k = 0; k < contacts.count; ++k) {
    quiver::rt::Contact ct = contacts.contacts[k];
    if (ct.body == i || ct.other == i) continue;
    if (ct.body > i) --ct.body;
    if (ct.other > i) --ct.other;
    contacts.contacts[kept++] = ct;
  }
  contacts.count = kept;
}

void qv_world::wakeSleptWith() {
  // The caller woke these (and may have moved them away from the rest of their group): the
  // bodies they fell asleep with wake too (a stack whose lowest is taken away must fall). A
  // group's id is its root's index when it fell asleep: no sleeper keeps an id once its root woke
  // (the world wakes whole groups, which hold the sleepers they fell asleep with, as sleepers do
  // not move; here, whole sleep groups).
  for (int i = 0; i < count; ++i) {
    const int group = instances[i]->sleepGroup;
    if (instances[i]->asleep || group < 0) continue;
    for (int j = 0; j < count; ++j)
      if (instances[j]->sleepGroup == group) instances[j]->wake(), instances[j]->sleepGroup = -1;
  }
}

void qv_world::begin(int i) {
  qv_instance& s = *instances[i];
  std::memcpy(s.startQ, s.q, sizeof(double) * s.r);
  s.beginStep();
  s.contacts.clear();
  slots[i].begun = true;
}

void qv_world::settle(double h) {
  for (int i = 0; i < count; ++i) slots[i].begun = false;
  if (!(config.sleep_speed > 0)) return;
  // Each group's shortest still time, at its root (the solve's groups: a group is all awake or all
  // asleep), then the groups still long enough (at least a step) fall asleep together; not beside
  // a moving collider, which would wake them at once.
  for (int i = 0; i < count; ++i) slots[i].groupStill = INFINITY;
  for (int i = 0; i < count; ++i) {
    qv_instance& s = *instances[i];
    if (s.asleep) continue;
    s.stillTime = quiver::rt::stillSpeed(s, h) < config.sleep_speed ? s.stillTime + h : 0;
    double& least = slots[bodies[i].group].groupStill;
    least = bodies[i].nearMovingCollider ? 0 : std::fmin(least, s.stillTime);
  }
  for (int i = 0; i < count; ++i) {
    const double still = slots[bodies[i].group].groupStill;
    if (!instances[i]->asleep && still > 0 && still >= config.sleep_time)
      quiver::rt::fallAsleep(*instances[i], bodies[i].group);
  }
}
