#include "apps/view/view_session.h"

#include <chrono>
#include <cmath>
#include <stdexcept>

#include <Eigen/Geometry>

namespace quiver::app {

bool ViewSettings::operator==(const ViewSettings& o) const {
  return step == o.step && gravity == o.gravity && springStiffness == o.springStiffness;
}

namespace {

// A spring that moves the object visibly without fighting the solver: pinned, three times the
// stiffness the whole mass has in the first mode (k = m omega_1^2); in flight, the whole mass on a
// 2.5 Hz spring (it hangs 4 cm below the cursor under gravity).
double defaultSpringStiffness(const RuntimeModel& model, const ReducedModes& modes, bool flying) {
  if (flying) return model.info().total_mass * std::pow(2 * M_PI * 2.5, 2);
  const double lambda = modes.eigenvalues.size() ? std::max(modes.eigenvalues[0], 1e-12) : 1.0;
  return 3 * model.info().total_mass * lambda;
}

} // namespace

ViewSession::ViewSession(const RuntimeModel& model, const ViewSettings& settings, const FlightSetup& flight)
    : model_(model), settings_(settings), modes_(reducedModes(model.get())), flightSetup_(flight) {
  if (settings_.springStiffness <= 0) settings_.springStiffness = defaultSpringStiffness(model, modes_, settings_.step.freeFlight);
  instance_ = std::make_unique<RuntimeInstance>(model_, instanceConfig(model_.get(), settings_.step));
  startFlight();
  applyLoads();
}

void ViewSession::startFlight() {
  flight_.reset();
  if (settings_.step.freeFlight) flight_ = std::make_unique<FlightWorld>(model_, *instance_, flightSetup_);
  const std::vector<unsigned> one = model_.triangles();
  triangles_.clear();
  for (int k = 0; k < bodyCount(); ++k)
    for (unsigned index : one) triangles_.push_back(index + static_cast<unsigned>(k * model_.info().vertex_count));
  renderTriangles_.clear();
  if (!model_.info().render_vertex_count) return;
  const std::vector<unsigned> render = model_.shownTriangles();
  for (int k = 0; k < bodyCount(); ++k)
    for (unsigned index : render) renderTriangles_.push_back(index + static_cast<unsigned>(k * model_.info().render_vertex_count));
}

void ViewSession::renderSurface(std::vector<float>& positions, std::vector<float>& normals) const {
  const size_t n = 3 * static_cast<size_t>(model_.info().render_vertex_count);
  positions.resize(n * bodyCount());
  normals.resize(positions.size());
  renderScratch_.resize(qv_model_render_scratch_size(model_.get()) / sizeof(double) + 1);
  for (int k = 0; k < bodyCount(); ++k)
    qv_instance_render(flight_ ? flight_->body(k).get() : instance_->get(), positions.data() + n * k, normals.data() + n * k,
                       renderScratch_.data());
}

void ViewSession::configure(const ViewSettings& wanted) {
  ViewSettings s = wanted;
  if (s.springStiffness <= 0) s.springStiffness = defaultSpringStiffness(model_, modes_, s.step.freeFlight);
  const qv_instance_config next = instanceConfig(model_.get(), s.step), now = instance_->config();
  const bool same = next.integrator == now.integrator && next.time_step == now.time_step &&
                    next.newton_iterations == now.newton_iterations && next.rayleigh_alpha == now.rayleigh_alpha &&
                    next.rayleigh_beta == now.rayleigh_beta && next.elasticity == now.elasticity &&
                    next.solver == now.solver && next.soft_contacts == now.soft_contacts;
  std::vector<double> q, v;  // the state a new instance continues from
  if (!same) {
    auto replacement = std::make_unique<RuntimeInstance>(model_, next);  // throws before anything changes
    q.resize(model_.info().r);
    v.resize(q.size());
    qv_instance_get_state(instance_->get(), q.data(), v.data(), nullptr);
    flight_.reset();  // it holds the old instance
    grabbed_ = -1;
    instance_ = std::move(replacement);
  }
  settings_ = s;
  if (!same) startFlight();  // in flight, the bodies start again
  applyLoads();  // before the state, so that its acceleration sees the loads
  if (!same && !flight_) qv_instance_set_state(instance_->get(), q.data(), v.data(), nullptr);
}

void ViewSession::applyLoads() {
  const double g[3] = {0, 0, settings_.gravity ? -kGravity : 0};
  if (flight_) {
    flight_->setGravity(g);
    return;  // the spring is a force each step (pullGrabbedBody)
  }
  qv_instance_set_gravity(instance_->get(), g);
  if (grabbed_ >= 0) {
    qv_instance_set_constraint(instance_->get(), 0, &grabbed_, 1, grabTarget_.data(), settings_.springStiffness);
  } else {
    qv_instance_clear_constraint(instance_->get(), 0);
  }
}

int ViewSession::advance(double seconds) {
  if (modeKind_ != ModeKind::None) {
    modeTime_ = std::fmod(modeTime_ + seconds, kModePeriod);
    return 0;
  }
  const double h = instance_->config().time_step;
  accumulator_ += seconds;
  int taken = 0;
  while (accumulator_ >= h && taken < kMaxStepsPerFrame) {
    const auto start = std::chrono::steady_clock::now();
    if (flight_) {
      pullGrabbedBody();
      resets_ += flight_->step();
    } else {
      resets_ += qv_instance_step(instance_->get()) == QV_STEP_RESET;
    }
    const double us = std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start).count();
    stepMicros_ = steps_ == 0 ? us : 0.98 * stepMicros_ + 0.02 * us;
    accumulator_ -= h;
    ++taken;
    ++steps_;
  }
  behind_ = accumulator_ >= h;
  if (behind_) accumulator_ = 0;  // drop what cannot be caught up, rather than spiral
  return taken;
}

ViewSession::FlightSpring ViewSession::flightSpring() const {
  const double m = model_.info().total_mass, h = instance_->config().time_step;
  // Explicit in the step: omega h <= 1 keeps it stable whatever the slider says.
  const double k = std::min(settings_.springStiffness, m / (h * h));
  return {k, 2 * std::sqrt(k * m)};
}

void ViewSession::pullGrabbedBody() {
  if (grabbed_ < 0) return;
  qv_instance* s = flight_->body(grabbedBody_).get();
  float at[3];
  qv_instance_positions_of(s, &grabbed_, 1, at);
  qv_rigid_state frame;
  qv_instance_get_rigid_state(s, &frame);
  const Eigen::Vector3d x(at[0], at[1], at[2]);
  const Eigen::Vector3d velocity = Eigen::Vector3d(frame.linear_velocity) +
                                   Eigen::Vector3d(frame.angular_velocity).cross(x - Eigen::Vector3d(frame.position));
  const FlightSpring spring = flightSpring();
  const Eigen::Vector3d force = spring.stiffness * (grabTarget_ - x) - spring.damping * velocity;
  qv_instance_add_vertex_force(s, grabbed_, force.data());
}

bool ViewSession::press(const Ray& ray, const Eigen::Vector3d& towardViewer) {
  std::vector<float> x;
  positions(x);
  const std::optional<SurfaceHit> hit = pickSurface(ray, x, triangles_);
  if (!hit) return false;
  const int v = hit->vertex, n = model_.info().vertex_count;
  dragPoint_ = hit->point;
  dragNormal_ = towardViewer.normalized();
  dragOffset_ = Eigen::Vector3d(x[3 * v], x[3 * v + 1], x[3 * v + 2]) - hit->point;
  grab(v % n, hit->point + dragOffset_, v / n);
  return true;
}

void ViewSession::drag(const Ray& ray) {
  if (grabbed_ < 0) return;
  if (const std::optional<Eigen::Vector3d> at = intersectPlane(ray, dragPoint_, dragNormal_))
    grab(grabbed_, *at + dragOffset_, grabbedBody_);
}

void ViewSession::grab(int vertex, const Eigen::Vector3d& target, int body) {
  grabbed_ = vertex;
  grabbedBody_ = body;
  grabTarget_ = target;
  applyLoads();
}

void ViewSession::release() {
  grabbed_ = -1;
  applyLoads();
}

void ViewSession::reset() {
  if (flight_) {
    flight_->restart();
  } else {
    qv_instance_reset(instance_->get());
  }
  accumulator_ = 0;
}

void ViewSession::showMode(ModeKind kind, int index, double amplitude) {
  if (kind != ModeKind::None && flight_) throw std::logic_error("the mode browser shows a model in place, not in flight");
  modeKind_ = kind;
  modeTime_ = 0;
  if (kind == ModeKind::None) return;
  const int r = model_.info().r;
  if (index < 0 || index >= r) throw std::out_of_range("mode " + std::to_string(index) + " of " + std::to_string(r));
  const Eigen::VectorXd q =
      kind == ModeKind::LinearMode ? Eigen::VectorXd(modes_.vectors.col(index)) : Eigen::VectorXd(Eigen::VectorXd::Unit(r, index));
  modeShape_ = withLargestDisplacement(model_.get(), q, amplitude);
}

void ViewSession::positions(std::vector<float>& out) const {
  const size_t n = 3 * static_cast<size_t>(model_.info().vertex_count);
  if (modeKind_ == ModeKind::None) {
    out.resize(n * bodyCount());
    for (int k = 0; k < bodyCount(); ++k)
      qv_instance_positions(flight_ ? flight_->body(k).get() : instance_->get(), out.data() + n * k);
    return;
  }
  const Eigen::VectorXd q = std::sin(2 * M_PI * modeTime_ / kModePeriod) * modeShape_;
  model_.positionsAt(q.data(), out);
}

void ViewSession::normals(const std::vector<float>& x, std::vector<float>& out) const {
  const size_t n = 3 * static_cast<size_t>(model_.info().vertex_count);
  out.resize(x.size());
  for (size_t k = 0; k < x.size() / n; ++k) qv_model_surface_normals(model_.get(), x.data() + n * k, out.data() + n * k);
}

ViewSession::Energies ViewSession::energies() const {
  Energies e{};
  for (int k = 0; k < bodyCount(); ++k) {
    double kinetic = 0, elastic = 0;
    qv_instance_energies(flight_ ? flight_->body(k).get() : instance_->get(), &kinetic, &elastic);
    e.kinetic += kinetic;
    e.elastic += elastic;
  }
  return e;
}

} // namespace quiver::app
