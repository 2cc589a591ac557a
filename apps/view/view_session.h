#pragma once
// What the viewer simulates and shows, without any window or GL: the runtime instance and its
// settings (or, in free flight, the bodies it flies among their colliders), fixed-rate stepping
// decoupled from the frame rate, the mouse spring, and the mode browser's animation. quiver-view
// draws it; tests drive it directly.
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "apps/support/flight_world.h"
#include "apps/support/reduced_modes.h"
#include "apps/support/runtime_model.h"
#include "apps/support/step_settings.h"
#include "apps/view/surface_pick.h"

namespace quiver::app {

enum class ModeKind { None = 0, LinearMode = 1, BasisVector = 2 };

struct ViewSettings {
  StepSettings step;
  bool gravity = false;
  double springStiffness = 0;    // N/m of the mouse spring; 0: scaled to the model (see ViewSession)

  bool operator==(const ViewSettings& o) const;
};

class ViewSession {
public:
  static constexpr int kMaxStepsPerFrame = 64;  // beyond this the simulation runs slower than real time
  static constexpr double kModePeriod = 1.5;    // s per oscillation in the mode browser, whatever the frequency

  // With settings.step.freeFlight, the bodies `flight` sets up fly (FlightWorld).
  ViewSession(const RuntimeModel& model, const ViewSettings& settings, const FlightSetup& flight = {});
  ViewSession(RuntimeModel&&, const ViewSettings&, const FlightSetup& = {}) = delete;  // the session keeps a reference

  const RuntimeModel& model() const { return model_; }
  const ViewSettings& settings() const { return settings_; }
  qv_instance_config config() const { return instance_->config(); }
  // Takes new settings; a new integrator, step, damping or elasticity makes a new instance that
  // continues from the current displacement and velocity (in flight: the bodies start again). Throws
  // if the runtime refuses them (the old settings stay).
  void configure(const ViewSettings& settings);

  // Consumes `seconds` of wall-clock time in whole steps of the time step (at most
  // kMaxStepsPerFrame; what cannot be caught up is dropped). Returns the steps taken. While a mode
  // is shown, only the mode's animation advances.
  int advance(double seconds);
  bool behindRealTime() const { return behind_; }

  // The mouse: a press on the surface grabs the vertex nearest the hit on a spring. The spring's
  // target keeps the vertex's offset from the hit point (a press held still pulls nothing) and
  // follows the cursor ray in the plane through the hit point facing `towardViewer`. In flight the
  // spring is a force on the grabbed body each step, damped as a whole-body critical spring (the
  // runtime's constraints hold pinned models only): it lifts, drags and, let go while moving, throws.
  bool press(const Ray& ray, const Eigen::Vector3d& towardViewer);  // false: the ray misses the model
  void drag(const Ray& ray);
  // The spring itself: pulls `vertex` of `body` toward `target`.
  void grab(int vertex, const Eigen::Vector3d& target, int body = 0);
  void release();
  bool grabbing() const { return grabbed_ >= 0; }
  int grabbedVertex() const { return grabbed_; }
  int grabbedBody() const { return grabbedBody_; }
  const Eigen::Vector3d& grabTarget() const { return grabTarget_; }

  void reset();  // back to rest; in flight, every body back where it started: it drops again
  // amplitude: largest vertex displacement, m. Not in flight (throws).
  void showMode(ModeKind kind, int index, double amplitude);
  ModeKind shownMode() const { return modeKind_; }
  const ReducedModes& modes() const { return modes_; }

  // What is drawn: the bodies' surfaces (one in place, or in flight all bodies one after the other),
  // their deformed positions (3 floats per vertex: the simulation, or the shown mode) and normals.
  int bodyCount() const { return flight_ ? flight_->bodyCount() : 1; }
  const FlightWorld* flight() const { return flight_.get(); }
  const qv_instance* body(int k) const { return flight_ ? flight_->body(k).get() : instance_->get(); }
  const std::vector<unsigned>& triangles() const { return triangles_; }
  void positions(std::vector<float>& out) const;
  void normals(const std::vector<float>& positions, std::vector<float>& out) const;
  // A model with a render mesh draws it instead while no mode is shown (every body's, one after
  // the other): its triangles, and its positions and normals now. The mouse still picks the
  // surface above.
  bool drawsRenderMesh() const { return model_.info().render_vertex_count > 0 && modeKind_ == ModeKind::None; }
  const std::vector<unsigned>& renderTriangles() const { return renderTriangles_; }
  void renderSurface(std::vector<float>& positions, std::vector<float>& normals) const;
  struct Energies {
    double kinetic, elastic;  // J
  };
  Energies energies() const;
  long stepsTaken() const { return steps_; }
  int resets() const { return resets_; }
  double stepMicros() const { return stepMicros_; }  // moving average of the step's cost
  double stableTimeStep() const { return qv_instance_stable_time_step(instance_->get()); }  // central differences'

private:
  void applyLoads();
  void startFlight();
  void pullGrabbedBody();  // in flight: this step's spring force

  // In flight, the mouse spring on a whole body: its stiffness (within the explicit step's limit)
  // and critical damping.
  struct FlightSpring {
    double stiffness, damping;
  };
  FlightSpring flightSpring() const;

  const RuntimeModel& model_;
  ViewSettings settings_;
  std::unique_ptr<RuntimeInstance> instance_;
  ReducedModes modes_;
  FlightSetup flightSetup_;
  std::unique_ptr<FlightWorld> flight_;  // in flight; body 0 is instance_
  std::vector<unsigned> triangles_, renderTriangles_;
  mutable std::vector<double> renderScratch_;  // qv_instance_render's
  double accumulator_ = 0;
  bool behind_ = false;
  int grabbed_ = -1, grabbedBody_ = 0;
  Eigen::Vector3d grabTarget_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d dragPoint_, dragNormal_, dragOffset_;  // the press: plane point and normal, vertex - hit
  long steps_ = 0;
  int resets_ = 0;
  double stepMicros_ = 0;
  ModeKind modeKind_ = ModeKind::None;
  Eigen::VectorXd modeShape_;  // reduced coordinates of the shown mode at full amplitude
  double modeTime_ = 0;
};

} // namespace quiver::app
