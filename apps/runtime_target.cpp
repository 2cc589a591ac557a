#include "apps/runtime_target.h"

#include <algorithm>
#include <iostream>
#include <stdexcept>

namespace quiver::app {

void warnAboveStableStep(const RuntimeInstance& instance) {
  const double stable = qv_instance_stable_time_step(instance.get());
  if (instance.config().integrator == QV_INTEGRATOR_CENTRAL_DIFFERENCES && instance.config().time_step > stable)
    std::cerr << "quiver: warning: --dt " << instance.config().time_step << " s is above central differences' stable step "
              << stable << " s (with this damping)\n";
}

RuntimeTarget::RuntimeTarget(const RuntimeModel& model, const StepSettings& settings)
    : model_(model), instance_(model, instanceConfig(model.get(), settings)) {
  warnAboveStableStep(instance_);
}

void RuntimeTarget::addVertexForce(int vertex, const double force[3]) {
  qv_instance_add_vertex_force(instance_.get(), vertex, force);
}

void RuntimeTarget::startFlight(const SimOptions& o) {
  flight_ = std::make_unique<FlightWorld>(model_, instance_, o.flight);
}

void RuntimeTarget::setGravity(const double g[3]) {
  if (flight_) {
    flight_->setGravity(g);
  } else {
    qv_instance_set_gravity(instance_.get(), g);
  }
}

void RuntimeTarget::setSprings(const std::vector<int>& vertices, const std::vector<double>& targets, double stiffness) {
  qv_instance_set_constraint(instance_.get(), 0, vertices.data(), static_cast<int>(vertices.size()), targets.data(),
                             stiffness);
}

void RuntimeTarget::clearSprings() { qv_instance_clear_constraint(instance_.get(), 0); }

int RuntimeTarget::step(int& newton) {
  const qv_step_status status = flight_ ? (flight_->step() ? QV_STEP_RESET : QV_STEP_OK) : qv_instance_step(instance_.get());
  qv_step_report report;
  qv_instance_last_step(instance_.get(), &report);
  newton = report.newton_iterations;
  indefinite_ += status == QV_STEP_INDEFINITE;
  heldBack_ += report.held_back;
  minimized_ += report.minimized;
  energyRemoved_ += report.energy_removed;
  if (flight_)
    for (const qv_contact& c : flight_->contacts()) maxPenetration_ = std::max(maxPenetration_, -c.depth);
  return status == QV_STEP_RESET ? 1 : 0;
}

void RuntimeTarget::displacement(int body, std::vector<double>& u) const {
  const std::vector<float> p = (flight_ ? flight_->body(body) : instance_).positions();
  const double* rest = qv_model_rest_positions(model_.get());
  u.resize(p.size());
  for (size_t i = 0; i < p.size(); ++i) u[i] = p[i] - rest[i];
}

std::vector<unsigned> RuntimeTarget::renderTriangles() const {
  return model_.info().render_vertex_count ? model_.shownTriangles() : std::vector<unsigned>{};
}

void RuntimeTarget::renderFrame(int body, std::vector<float>& positions, std::vector<float>& normals) const {
  const size_t V = static_cast<size_t>(model_.info().render_vertex_count);
  positions.resize(3 * V);
  normals.resize(3 * V);
  std::vector<double> scratch(qv_model_render_scratch_size(model_.get()) / sizeof(double) + 1);
  qv_instance_render((flight_ ? flight_->body(body) : instance_).get(), positions.data(), normals.data(), scratch.data());
}

void RuntimeTarget::energies(double& kinetic, double& elastic) const {
  qv_instance_energies(instance_.get(), &kinetic, &elastic);
}

} // namespace quiver::app
