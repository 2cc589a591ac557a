#pragma once
// The runtime library as a scenario target: what `quiver sim` measures and `quiver render` draws.
#include <memory>
#include <string>
#include <vector>

#include "apps/sim_scenario.h"
#include "apps/support/runtime_model.h"

namespace quiver::app {

// Warns on stderr ("quiver: warning: ...") when `instance` steps by central differences above its
// stable step.
void warnAboveStableStep(const RuntimeInstance& instance);

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
  int bodyCount() const override { return flight_ ? flight_->bodyCount() : 1; }
  void displacement(int body, std::vector<double>& u) const override;
  std::vector<unsigned> renderTriangles() const override;
  void renderFrame(int body, std::vector<float>& positions, std::vector<float>& normals) const override;
  void energies(double& kinetic, double& elastic) const override;
  double timeStep() const override { return instance_.config().time_step; }

  const RuntimeInstance& instance() const { return instance_; }
  // In flight: its bodies (body 0 is instance()) and colliders; null before startFlight().
  const FlightWorld* flight() const { return flight_.get(); }
  int indefiniteSteps() const { return indefinite_; }
  int heldBackSteps() const { return heldBack_; }
  int minimizedSteps() const { return minimized_; }  // fixed Newton steps the minimiser took
  double energyRemoved() const { return energyRemoved_; }  // J, by the minimising solver's energy budget
  double maxPenetration() const { return maxPenetration_; }  // m, the deepest contact seen

private:
  const RuntimeModel& model_;
  RuntimeInstance instance_;
  int indefinite_ = 0, heldBack_ = 0, minimized_ = 0;
  double energyRemoved_ = 0;
  std::unique_ptr<FlightWorld> flight_;
  double maxPenetration_ = 0;
};

} // namespace quiver::app
