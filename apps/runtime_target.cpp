#include "apps/runtime_target.h"

#include <algorithm>
#include <iostream>
#include <stdexcept>

namespace quiver::app {

RuntimeTarget::RuntimeTarget(const RuntimeModel& model, const StepSettings& settings)
    : model_(model), instance_(model, instanceConfig(model.get(), settings)) {
  const double stable = qv_instance_stable_time_step(instance_.get());
  if (instance_.config().integrator == QV_INTEGRATOR_CENTRAL_DIFFERENCES && instance_.config().time_step > stable)
    std::cerr << "quiver: warning: --dt " << instance_.config().time_step << " s is above central differences' stable step "
              << stable << " s\n";
}

void RuntimeTarget::addVertexForce(int vertex, const double force[3]) {
  qv_instance_add_vertex_force(instance_.get(), vertex, force);
}

void RuntimeTarget::startFlight(const SimOptions& o) {
  qv_rigid_state state;
  qv_instance_get_rigid_state(instance_.get(), &state);  // the pose as baked
  for (int a = 0; a < 3; ++a) {
    state.position[a] += o.position[a];
    state.linear_velocity[a] = o.velocity[a];
    state.angular_velocity[a] = o.angularVelocity[a];
  }
  if (qv_instance_set_rigid_state(instance_.get(), &state) != QV_OK)
    throw std::runtime_error("--position, --velocity and --angular-velocity must be finite");
  for (const std::string& text : o.colliders) {
    colliders_.add(text, o.friction, o.restitution);
    if (qv_instance_set_colliders(instance_.get(), &colliders_[colliders_.size() - 1], 1) != QV_OK)
      throw std::runtime_error("--collider '" + text + "': sizes must be positive, a plane's normal not zero");
  }
  if (qv_instance_set_colliders(instance_.get(), colliders_.data(), colliders_.size()) != QV_OK)
    throw std::runtime_error("--friction and --restitution: mu >= 0, restitution in 0..1");
  contacts_.resize(static_cast<size_t>(instance_.config().max_contacts));
}

void RuntimeTarget::setGravity(const double g[3]) { qv_instance_set_gravity(instance_.get(), g); }

void RuntimeTarget::setSprings(const std::vector<int>& vertices, const std::vector<double>& targets, double stiffness) {
  qv_instance_set_constraint(instance_.get(), 0, vertices.data(), static_cast<int>(vertices.size()), targets.data(),
                             stiffness);
}

void RuntimeTarget::clearSprings() { qv_instance_clear_constraint(instance_.get(), 0); }

int RuntimeTarget::step(int& newton) {
  const qv_step_status status = qv_instance_step(instance_.get());
  qv_step_report report;
  qv_instance_last_step(instance_.get(), &report);
  newton = report.newton_iterations;
  indefinite_ += status == QV_STEP_INDEFINITE;
  heldBack_ += report.held_back;
  energyRemoved_ += report.energy_removed;
  const int touching = std::min(qv_instance_contacts(instance_.get(), contacts_.data(), static_cast<int>(contacts_.size())),
                                static_cast<int>(contacts_.size()));
  for (int j = 0; j < touching; ++j) maxPenetration_ = std::max(maxPenetration_, -contacts_[j].depth);
  return status == QV_STEP_RESET ? 1 : 0;
}

void RuntimeTarget::displacement(std::vector<double>& u) const {
  const std::vector<float> p = instance_.positions();
  const double* rest = qv_model_rest_positions(model_.get());
  u.resize(p.size());
  for (size_t i = 0; i < p.size(); ++i) u[i] = p[i] - rest[i];
}

void RuntimeTarget::energies(double& kinetic, double& elastic) const {
  qv_instance_energies(instance_.get(), &kinetic, &elastic);
}

} // namespace quiver::app
