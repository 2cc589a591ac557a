#include "apps/view/view_session.h"

#include <chrono>
#include <cmath>
#include <stdexcept>

namespace quiver::app {

bool ViewSettings::operator==(const ViewSettings& o) const {
  return step == o.step && gravity == o.gravity && springStiffness == o.springStiffness;
}

namespace {

// A spring that moves the object visibly without fighting the solver: three times the stiffness
// the whole mass has in the first mode (k = m omega_1^2).
double defaultSpringStiffness(const RuntimeModel& model, const ReducedModes& modes) {
  const double lambda = modes.eigenvalues.size() ? std::max(modes.eigenvalues[0], 1e-12) : 1.0;
  return 3 * model.info().total_mass * lambda;
}

} // namespace

ViewSession::ViewSession(const RuntimeModel& model, const ViewSettings& settings)
    : model_(model), settings_(settings), modes_(reducedModes(model.get())) {
  if (settings_.springStiffness <= 0) settings_.springStiffness = defaultSpringStiffness(model, modes_);
  instance_ = std::make_unique<RuntimeInstance>(model_, instanceConfig(model_.get(), settings_.step));
  applyLoads();
}

void ViewSession::configure(const ViewSettings& wanted) {
  ViewSettings s = wanted;
  if (s.springStiffness <= 0) s.springStiffness = defaultSpringStiffness(model_, modes_);
  const qv_instance_config next = instanceConfig(model_.get(), s.step), now = instance_->config();
  const bool same = next.integrator == now.integrator && next.time_step == now.time_step &&
                    next.newton_iterations == now.newton_iterations && next.rayleigh_alpha == now.rayleigh_alpha &&
                    next.rayleigh_beta == now.rayleigh_beta && next.elasticity == now.elasticity &&
                    next.solver == now.solver;
  std::vector<double> q, v;  // the state a new instance continues from
  if (!same) {
    auto replacement = std::make_unique<RuntimeInstance>(model_, next);  // throws before anything changes
    q.resize(model_.info().r);
    v.resize(q.size());
    qv_instance_get_state(instance_->get(), q.data(), v.data(), nullptr);
    instance_ = std::move(replacement);
  }
  settings_ = s;
  applyLoads();  // before the state, so that its acceleration sees the loads
  if (!same) qv_instance_set_state(instance_->get(), q.data(), v.data(), nullptr);
}

void ViewSession::applyLoads() {
  const double g[3] = {0, 0, settings_.gravity ? -kGravity : 0};
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
    resets_ += qv_instance_step(instance_->get()) == QV_STEP_RESET;
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

bool ViewSession::press(const Ray& ray, const Eigen::Vector3d& towardViewer) {
  std::vector<float> x;
  positions(x);
  const std::optional<SurfaceHit> hit = pickSurface(ray, x, model_.triangles());
  if (!hit) return false;
  const int v = hit->vertex;
  dragPoint_ = hit->point;
  dragNormal_ = towardViewer.normalized();
  dragOffset_ = Eigen::Vector3d(x[3 * v], x[3 * v + 1], x[3 * v + 2]) - hit->point;
  grab(v, hit->point + dragOffset_);
  return true;
}

void ViewSession::drag(const Ray& ray) {
  if (grabbed_ < 0) return;
  if (const std::optional<Eigen::Vector3d> at = intersectPlane(ray, dragPoint_, dragNormal_)) grab(grabbed_, *at + dragOffset_);
}

void ViewSession::grab(int vertex, const Eigen::Vector3d& target) {
  grabbed_ = vertex;
  grabTarget_ = target;
  applyLoads();
}

void ViewSession::release() {
  grabbed_ = -1;
  applyLoads();
}

void ViewSession::reset() {
  qv_instance_reset(instance_->get());
  accumulator_ = 0;
}

void ViewSession::showMode(ModeKind kind, int index, double amplitude) {
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
  if (modeKind_ == ModeKind::None) {
    out.resize(3 * static_cast<size_t>(model_.info().vertex_count));
    qv_instance_positions(instance_->get(), out.data());
    return;
  }
  const Eigen::VectorXd q = std::sin(2 * M_PI * modeTime_ / kModePeriod) * modeShape_;
  model_.positionsAt(q.data(), out);
}

ViewSession::Energies ViewSession::energies() const {
  Energies e{};
  qv_instance_energies(instance_->get(), &e.kinetic, &e.elastic);
  return e;
}

} // namespace quiver::app
