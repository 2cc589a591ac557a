#pragma once
// The runtime library as a scenario target: what `quiver sim` measures and `quiver render` draws.
#include <memory>
#include <string>
#include <vector>

#include "apps/sim_scenario.h"
#include "apps/support/collider_set.h"
#include "apps/support/runtime_model.h"

namespace quiver::app {

class RuntimeTarget : public ScenarioTarget {
public:
  RuntimeTarget(const RuntimeModel& model, const StepSettings& settings);
  RuntimeTarget(RuntimeModel&&, const StepSettings&) = delete;  // kept by reference
  void addVertexForce(int vertex, const double force[3]) override;
  void setGravity(const double acceleration[3]) override;
  void startFlight(const SimOptions& options) override;
  void setSprings(const std::vector<int>& vertices, const std::vector<double>& targets, double stiffness) override;
  void clearSprings() override;
  int step(int& newtonIterations) override;
  void displacement(std::vector<double>& u) const override;
  void energies(double& kinetic, double& elastic) const override;
  double timeStep() const override { return instance_.config().time_step; }

  const RuntimeInstance& instance() const { return instance_; }
  // With --pile N: N bodies in one world (body 0 is instance()); otherwise 1.
  int bodyCount() const { return 1 + static_cast<int>(copies_.size()); }
  const RuntimeInstance& body(int i) const { return i == 0 ? instance_ : *copies_[static_cast<size_t>(i - 1)]; }
  int indefiniteSteps() const { return indefinite_; }
  int heldBackSteps() const { return heldBack_; }
  double energyRemoved() const { return energyRemoved_; }  // J, by the minimising solver's energy budget
  double maxPenetration() const { return maxPenetration_; }  // m, the deepest contact seen
  const ColliderSet& colliders() const { return colliders_; }

private:
  const RuntimeModel& model_;
  RuntimeInstance instance_;
  int indefinite_ = 0, heldBack_ = 0;
  double energyRemoved_ = 0;
  ColliderSet colliders_;  // the instance (or the world) reads them by pointer
  struct WorldRelease {
    void operator()(qv_world* world) const { qv_world_destroy(world); }
  };
  std::vector<std::unique_ptr<RuntimeInstance>> copies_;  // --pile: the other bodies
  std::unique_ptr<qv_world, WorldRelease> world_;          // --pile: all bodies
  std::vector<qv_contact> contacts_;
  double maxPenetration_ = 0;
};

} // namespace quiver::app
