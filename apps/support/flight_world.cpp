#include "apps/support/flight_world.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "apps/support/mesh_options.h"

namespace quiver::app {

namespace {

// Where body k of `count` goes: layers of four on a 2 x 2 grid spaced by the model's width, each
// layer turned a quarter about z from the one below and raised by 1.5 x the model's height, each
// body turned a little more so that the pile does not stand in perfect columns. Spread: side by
// side on a square grid, 1.2 x the model's diagonal apart (apart for good), each turned a little.
// A single body stays.
void pileSlot(const qv_model_info& info, int k, int count, bool spread, double offset[3], double quaternion[4]) {
  offset[0] = offset[1] = offset[2] = 0;
  quaternion[0] = 1, quaternion[1] = quaternion[2] = quaternion[3] = 0;
  if (count == 1) return;
  const double dx = info.bbox_max[0] - info.bbox_min[0], dy = info.bbox_max[1] - info.bbox_min[1],
               dz = info.bbox_max[2] - info.bbox_min[2];
  if (spread) {
    const int side = static_cast<int>(std::ceil(std::sqrt(count)));
    const double spacing = 1.2 * std::sqrt(dx * dx + dy * dy + dz * dz), yaw = 0.15 * (k % 7);
    offset[0] = (k % side - (side - 1) / 2.0) * spacing;
    offset[1] = (k / side - (side - 1) / 2.0) * spacing;
    quaternion[0] = std::cos(yaw / 2), quaternion[3] = std::sin(yaw / 2);
    return;
  }
  const double spacing = 0.6 * std::hypot(dx, dy);
  const int layer = k / 4, slot = k % 4;
  offset[0] = (slot == 1 || slot == 3 ? 1 : -1) * spacing;
  offset[1] = (slot >= 2 ? 1 : -1) * spacing;
  offset[2] = 1.5 * dz * layer;
  const double yaw = M_PI / 2 * layer + 0.15 * slot;
  quaternion[0] = std::cos(yaw / 2), quaternion[3] = std::sin(yaw / 2);
}

} // namespace

FlightSetup::FlightSetup() {
  qv_world_config world;
  qv_world_config_init(&world);
  sleepSpeed = world.sleep_speed;
}

void FlightSetup::addTo(CLI::App& app) {
  app.add_option("--position", position, "Free flight: start translated by x,y,z (m) from where the model was baked")
      ->delimiter(',')->expected(3);
  app.add_option("--velocity", velocity, "Free flight: initial velocity vx,vy,vz, m/s")->delimiter(',')->expected(3);
  app.add_option("--collider", colliders,
                 "Free flight: a collider, repeatable: plane:nx,ny,nz,d (points with n.x = d), sphere:x,y,z,radius, "
                 "box:cx,cy,cz,hx,hy,hz (axis-aligned), capsule:x0,y0,z0,x1,y1,z1,radius, mesh:FILE[,x,y,z] (a closed "
                 "surface: OBJ, STL, PLY, glTF, FBX, ... or a tet mesh's boundary; moved by x,y,z)");
  app.add_option("--pile", pile,
                 "Free flight: N copies of the model in layers of four above --position, in one world where they "
                 "touch each other and the colliders (loads act on the first)")
      ->capture_default_str()
      ->check(CLI::Range(1, 4096));
  app.add_option("--friction", friction, "Free flight: Coulomb friction of the colliders")->capture_default_str()->check(NonNegative);
  app.add_option("--restitution", restitution, "Free flight: restitution of the colliders, 0..1")
      ->capture_default_str()
      ->check(Between(0.0, 1.0));
  app.add_flag("--spread", spread, "Free flight, --pile: the N copies side by side on a square grid, apart, not piled");
  app.add_option("--sleep-speed", sleepSpeed,
                 "Free flight, --pile: bodies that could touch, all slower than this (m/s) for half a second, sleep "
                 "until something wakes them; 0: never")
      ->capture_default_str()
      ->check(NonNegative);
  app.add_option("--angular-velocity", angularVelocity, "Free flight: initial spin wx,wy,wz, rad/s (world axes)")
      ->delimiter(',')->expected(3);
}

void FlightSetup::check(bool freeFlight) const {
  const FlightSetup none;
  if (!freeFlight && (position != none.position || velocity != none.velocity || angularVelocity != none.angularVelocity ||
                      !colliders.empty() || pile != 1 || friction != none.friction || restitution != none.restitution))
    throw std::runtime_error(
        "--position, --velocity, --angular-velocity, --collider, --pile, --friction and --restitution need --free");
  if (pile == 1 && (spread || sleepSpeed != none.sleepSpeed)) throw std::runtime_error("--spread and --sleep-speed need --pile N");
}

FlightWorld::FlightWorld(const RuntimeModel& model, const RuntimeInstance& first, const FlightSetup& o) : first_(first) {
  const int count = std::max(1, o.pile);
  if (count > 1) {
    qv_world_config config;
    qv_world_config_init(&config);
    config.max_instances = count;
    config.max_contacts = 64 * count;
    config.friction = o.friction;
    config.restitution = o.restitution;
    config.sleep_speed = o.sleepSpeed;
    qv_world* world = nullptr;
    if (qv_world_create(&config, nullptr, &world) != QV_OK) throw std::runtime_error("--pile: out of memory");
    world_.reset(world);
    if (o.threads > 1) {
      pool_ = std::make_unique<JobPool>(o.threads);
      runner_ = pool_->runner();
      qv_world_set_jobs(world, &runner_);
    }
  }
  for (int k = 0; k < count; ++k) {
    if (k > 0) copies_.push_back(std::make_unique<RuntimeInstance>(model, first.config()));
    qv_instance* s = body(k).get();
    qv_rigid_state state;
    qv_instance_get_rigid_state(s, &state);  // the pose as baked
    double offset[3], turn[4];
    pileSlot(model.info(), k, count, o.spread, offset, turn);
    for (int a = 0; a < 3; ++a) {  // turned about the baked centre of mass, then moved
      state.position[a] += o.position[a] + offset[a];
      state.linear_velocity[a] = o.velocity[a];
      state.angular_velocity[a] = o.angularVelocity[a];
    }
    std::copy(turn, turn + 4, state.orientation);
    if (qv_instance_set_rigid_state(s, &state) != QV_OK)
      throw std::runtime_error("--position, --velocity and --angular-velocity must be finite");
    if (world_ && qv_world_add(world_.get(), s, nullptr) != QV_OK)
      throw std::runtime_error("--pile: cannot add body " + std::to_string(k));
  }
  const auto use = [&](const qv_collider* colliders, int n) {
    return world_ ? qv_world_set_colliders(world_.get(), colliders, n) : qv_instance_set_colliders(first_.get(), colliders, n);
  };
  for (const std::string& text : o.colliders) {
    colliders_.add(text, o.friction, o.restitution);
    if (use(&colliders_[colliders_.size() - 1], 1) != QV_OK)
      throw std::runtime_error("--collider '" + text + "': sizes must be positive, a plane's normal not zero");
  }
  if (use(colliders_.data(), colliders_.size()) != QV_OK)
    throw std::runtime_error("--friction and --restitution: mu >= 0, restitution in 0..1");
  contactCapacity_ = world_ ? 64 * count : first.config().max_contacts;
}

void FlightWorld::setGravity(const double g[3]) {
  for (int k = 0; k < bodyCount(); ++k) qv_instance_set_gravity(body(k).get(), g);
}

int FlightWorld::step() {
  if (world_) return qv_world_step(world_.get());
  return qv_instance_step(first_.get()) == QV_STEP_RESET ? 1 : 0;
}

int FlightWorld::asleepCount() const {
  int asleep = 0;
  for (int k = 0; k < bodyCount(); ++k) asleep += qv_instance_asleep(body(k).get());
  return asleep;
}

const std::vector<qv_contact>& FlightWorld::contacts() {
  contacts_.resize(static_cast<size_t>(contactCapacity_));
  const int n = world_ ? qv_world_contacts(world_.get(), contacts_.data(), contactCapacity_)
                       : qv_instance_contacts(first_.get(), contacts_.data(), contactCapacity_);
  contacts_.resize(static_cast<size_t>(std::min(n, contactCapacity_)));
  return contacts_;
}

void FlightWorld::restart() {
  for (int k = 0; k < bodyCount(); ++k) qv_instance_reset(body(k).get());
}

} // namespace quiver::app
