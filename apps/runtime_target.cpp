#include "apps/runtime_target.h"

#include <algorithm>
#include <cmath>
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

namespace {

// Where --pile puts body k: layers of four on a 2 x 2 grid spaced by the model's width, each layer
// turned a quarter about z from the one below and raised by 1.5 x the model's height, each body
// turned a little more so that the pile does not stand in perfect columns. Body 0 of a single body
// stays where it is.
void pileSlot(const qv_model_info& info, int k, int count, double offset[3], double quaternion[4]) {
  if (count == 1) {
    offset[0] = offset[1] = offset[2] = 0;
    quaternion[0] = 1, quaternion[1] = quaternion[2] = quaternion[3] = 0;
    return;
  }
  const double dx = info.bbox_max[0] - info.bbox_min[0], dy = info.bbox_max[1] - info.bbox_min[1],
               dz = info.bbox_max[2] - info.bbox_min[2];
  const double spacing = 0.6 * std::hypot(dx, dy), layer = k / 4, slot = k % 4;
  offset[0] = (slot == 1 || slot == 3 ? 1 : -1) * spacing;
  offset[1] = (slot >= 2 ? 1 : -1) * spacing;
  offset[2] = 1.5 * dz * layer;
  const double yaw = M_PI / 2 * layer + 0.15 * slot;
  quaternion[0] = std::cos(yaw / 2), quaternion[1] = quaternion[2] = 0, quaternion[3] = std::sin(yaw / 2);
}

} // namespace

void RuntimeTarget::startFlight(const SimOptions& o) {
  const int count = std::max(1, o.pile);
  if (count > 1) {
    qv_world_config config;
    qv_world_config_init(&config);
    config.max_instances = count;
    config.max_contacts = 64 * count;
    config.friction = o.friction;
    config.restitution = o.restitution;
    qv_world* world = nullptr;
    if (qv_world_create(&config, nullptr, &world) != QV_OK) throw std::runtime_error("--pile: out of memory");
    world_.reset(world);
  }
  for (int k = 0; k < count; ++k) {
    if (k > 0) copies_.push_back(std::make_unique<RuntimeInstance>(model_, instance_.config()));
    qv_instance* s = body(k).get();
    qv_rigid_state state;
    qv_instance_get_rigid_state(s, &state);  // the pose as baked
    double offset[3], turn[4];
    pileSlot(model_.info(), k, count, offset, turn);
    // Turned about the baked centre of mass, then moved.
    for (int a = 0; a < 3; ++a) {
      state.position[a] += o.position[a] + offset[a];
      state.linear_velocity[a] = o.velocity[a];
      state.angular_velocity[a] = o.angularVelocity[a];
    }
    std::copy(turn, turn + 4, state.orientation);
    if (qv_instance_set_rigid_state(s, &state) != QV_OK)
      throw std::runtime_error("--position, --velocity and --angular-velocity must be finite");
    if (world_ && qv_world_add(world_.get(), s, nullptr) != QV_OK) throw std::runtime_error("--pile: cannot add body " + std::to_string(k));
  }
  const auto use = [&](const qv_collider* colliders, int n) {
    return world_ ? qv_world_set_colliders(world_.get(), colliders, n) : qv_instance_set_colliders(instance_.get(), colliders, n);
  };
  for (const std::string& text : o.colliders) {
    colliders_.add(text, o.friction, o.restitution);
    if (use(&colliders_[colliders_.size() - 1], 1) != QV_OK)
      throw std::runtime_error("--collider '" + text + "': sizes must be positive, a plane's normal not zero");
  }
  if (use(colliders_.data(), colliders_.size()) != QV_OK)
    throw std::runtime_error("--friction and --restitution: mu >= 0, restitution in 0..1");
  contacts_.resize(static_cast<size_t>(world_ ? 64 * count : instance_.config().max_contacts));
}

void RuntimeTarget::setGravity(const double g[3]) {
  for (int k = 0; k < bodyCount(); ++k) qv_instance_set_gravity(body(k).get(), g);
}

void RuntimeTarget::setSprings(const std::vector<int>& vertices, const std::vector<double>& targets, double stiffness) {
  qv_instance_set_constraint(instance_.get(), 0, vertices.data(), static_cast<int>(vertices.size()), targets.data(),
                             stiffness);
}

void RuntimeTarget::clearSprings() { qv_instance_clear_constraint(instance_.get(), 0); }

int RuntimeTarget::step(int& newton) {
  const qv_step_status status = world_ ? (qv_world_step(world_.get()) ? QV_STEP_RESET : QV_STEP_OK)
                                      : qv_instance_step(instance_.get());
  qv_step_report report;
  qv_instance_last_step(instance_.get(), &report);
  newton = report.newton_iterations;
  indefinite_ += status == QV_STEP_INDEFINITE;
  heldBack_ += report.held_back;
  energyRemoved_ += report.energy_removed;
  const int capacity = static_cast<int>(contacts_.size());
  const int touching = std::min(world_ ? qv_world_contacts(world_.get(), contacts_.data(), capacity)
                                       : qv_instance_contacts(instance_.get(), contacts_.data(), capacity),
                                capacity);
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
