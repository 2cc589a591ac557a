#pragma once
// The tools' free flight: one flying instance, or with --pile N, N of them in one qv_world, with the
// --collider colliders, started where the options say. What `quiver sim`, `quiver render` and the
// viewer fly.
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "apps/support/collider_set.h"
#include "apps/support/job_pool.h"
#include "apps/support/runtime_model.h"

namespace quiver::app {

struct FlightSetup {
  std::vector<double> position{0, 0, 0};         // m, the model translated from where it was baked
  std::vector<double> velocity{0, 0, 0};         // m/s
  std::vector<double> angularVelocity{0, 0, 0};  // rad/s, about the centre of mass
  std::vector<std::string> colliders;            // --collider TYPE:NUMBERS (ColliderSet::add)
  int pile = 1;                                  // --pile N: N copies in one world, touching each other
  bool spread = false;                           // --spread: the copies side by side, apart
  double friction = 0.5;                         // Coulomb mu of every collider (and between bodies)
  double restitution = 0.2;                      // of every collider (and between bodies), 0..1
  double sleepSpeed = 0;                         // --pile: qv_world_config.sleep_speed, m/s (0: never); the runtime's default
  int threads = 1;                               // --pile: the world's jobs on this many threads (qv_world_set_jobs);
                                                 // `quiver sim --threads` sets it, not addTo()

  FlightSetup();

  // --position, --velocity, --angular-velocity, --collider, --pile, --spread, --friction, --restitution,
  // --sleep-speed.
  void addTo(CLI::App& app);
  // Throws naming the options given that need --free (when not flying) or --pile N.
  void check(bool freeFlight) const;
};

class FlightWorld {
public:
  // Body 0 is `first` (kept by reference, flying); the others are copies with its config, placed in
  // layers of four above it, each turned a quarter from the layer below. Throws naming the option at fault.
  FlightWorld(const RuntimeModel& model, const RuntimeInstance& first, const FlightSetup& setup);
  FlightWorld(const FlightWorld&) = delete;
  FlightWorld& operator=(const FlightWorld&) = delete;

  int bodyCount() const { return 1 + static_cast<int>(copies_.size()); }
  const RuntimeInstance& body(int k) const { return k == 0 ? first_ : *copies_[static_cast<size_t>(k - 1)]; }
  const ColliderSet& colliders() const { return colliders_; }
  int asleepCount() const;
  void setGravity(const double acceleration[3]);
  // One step of every body; the number that reset.
  int step();
  // The last step's contacts (a view into the world's or the instance's; valid until the next step).
  const std::vector<qv_contact>& contacts();
  // Every body back where it started, at rest (the viewer's "drop again").
  void restart();

private:
  struct WorldRelease {
    void operator()(qv_world* world) const { qv_world_destroy(world); }
  };
  const RuntimeInstance& first_;
  std::vector<std::unique_ptr<RuntimeInstance>> copies_;
  std::unique_ptr<JobPool> pool_;                  // with --threads above 1
  qv_job_runner runner_{};                         // the world reads it by pointer
  std::unique_ptr<qv_world, WorldRelease> world_;  // with more than one body
  ColliderSet colliders_;                          // the instance or the world reads them by pointer
  std::vector<qv_contact> contacts_;
  int contactCapacity_ = 0;
};

} // namespace quiver::app
