#pragma once
// qv_world: flying instances that touch each other and the world's colliders (contact.h). One
// block from the caller's allocator, sized by its config; the step allocates nothing.
#include "contact.h"

namespace quiver::rt {

// A body's part in a world step: whether its step has begun; at a group's root, the group's
// shortest still time (qv_instance::stillTime).
struct WorldSlot {
  bool begun = false;
  bool reset = false;  // its step's end reset it (a blown-up state)
  double groupStill = 0;
};

} // namespace quiver::rt

struct qv_world {
  qv_allocator allocator;
  qv_world_config config;
  qv_instance** instances = nullptr;  // the caller's, in qv_world_add's order
  int count = 0;
  quiver::rt::ContactBody* bodies = nullptr;
  quiver::rt::WorldSlot* slots = nullptr;
  quiver::rt::BroadPhase broad;
  quiver::rt::ContactList contacts;
  const qv_collider* colliders = nullptr;  // the caller's (qv_world_set_colliders)
  int colliderCount = 0;
  const qv_job_runner* jobs = nullptr;     // the caller's (qv_world_set_jobs); null: the calling thread

  // Calls part(i) for each i in [0, count), in jobs' contiguous ranges when the world has jobs.
  void forEachInstance(void (*part)(qv_world&, int));

  // Each awake instance's frame forces, one contact solve over all, then each move and deformation;
  // then the groups that have been still long enough fall asleep.
  int step();
  // The snapshot (qv_world_save_snapshot): how many instances, then each one's sleep (asleep, still
  // time, sleep group) and state (qv_instance::saveState()), then the last step's contacts
  // (contact_list.h), as doubles. Bytes: the most it takes (every contact held), and what one took.
  size_t snapshotSize() const;
  size_t saveSnapshot(double* out) const;
  bool restoreSnapshot(const double* in, size_t bytes);
  // Takes instance i out (qv_world_remove): the later ones move down an index, and the last
  // step's contacts and sleep groups with them.
  void remove(int i);
  void wakeSleptWith();
  void begin(int i);
  void settle(double h);
};

namespace quiver::rt {

bool validWorldConfig(const qv_world_config& config);
void defaultWorldConfig(qv_world_config& config);
qv_world* createWorld(const qv_world_config& config, const qv_allocator& allocator);
void destroyWorld(qv_world* world);

} // namespace quiver::rt
