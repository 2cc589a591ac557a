// `quiver sim`: the scenario on the runtime library, as a game would drive it.
#include <iostream>

#include <nlohmann/json.hpp>

#include "apps/sim_scenario.h"
#include "formats/mesh/read_mesh.h"
#include "formats/model/qvr.h"
#include "quiver/quiver.h"

namespace quiver::app {

namespace {

class RuntimeTarget : public ScenarioTarget {
public:
  RuntimeTarget(const std::string& path, const std::string& integrator, const std::string& elasticity,
                const SimOptions& o) {
    char message[1024] = "";
    if (qv_model_load_file(path.c_str(), nullptr, nullptr, &model_, message, sizeof message) != QV_OK)
      throw std::runtime_error(message);
    qv_model_get_info(model_, &info_);
    qv_instance_config_init(&config_, model_);
    config_.integrator = integrator == "euler"     ? QV_INTEGRATOR_BACKWARD_EULER
                         : integrator == "central" ? QV_INTEGRATOR_CENTRAL_DIFFERENCES
                                                   : QV_INTEGRATOR_IMPLICIT_NEWMARK;
    if (o.timeStep > 0) config_.time_step = o.timeStep;
    config_.newton_iterations = o.newton;
    config_.linear = elasticity == "linear";
    config_.warping = elasticity == "warping";
    if (o.alpha >= 0) config_.rayleigh_alpha = o.alpha;
    if (o.beta >= 0) config_.rayleigh_beta = o.beta;
    if (qv_instance_create(model_, &config_, nullptr, &instance_) != QV_OK)
      throw std::runtime_error(config_.warping && !info_.has_modal_rotations
                                   ? path + " has no modal rotations (bake it again for modal warping)"
                                   : "invalid simulation settings (time step, Newton iterations, damping)");
    if (config_.integrator == QV_INTEGRATOR_CENTRAL_DIFFERENCES && config_.time_step > qv_instance_stable_time_step(instance_))
      std::cerr << "quiver: warning: --dt " << config_.time_step << " s is above central differences' stable step "
                << qv_instance_stable_time_step(instance_) << " s\n";
  }
  ~RuntimeTarget() override {
    qv_instance_destroy(instance_);
    qv_model_destroy(model_);
  }
  void addVertexForce(int vertex, const double force[3]) override { qv_instance_add_vertex_force(instance_, vertex, force); }
  void setGravity(const double g[3]) override { qv_instance_set_gravity(instance_, g); }
  void setSprings(const std::vector<int>& vertices, const std::vector<double>& targets, double stiffness) override {
    qv_instance_set_constraint(instance_, 0, vertices.data(), static_cast<int>(vertices.size()), targets.data(), stiffness);
  }
  void clearSprings() override { qv_instance_clear_constraint(instance_, 0); }
  int step(int& newton) override {
    newton = config_.integrator == QV_INTEGRATOR_CENTRAL_DIFFERENCES ? 0 : config_.newton_iterations;
    const qv_step_status status = qv_instance_step(instance_);
    indefinite_ += status == QV_STEP_INDEFINITE;
    return status == QV_STEP_RESET ? 1 : 0;
  }
  void displacement(std::vector<double>& u) const override {
    std::vector<float> p(3 * static_cast<size_t>(info_.vertex_count));
    qv_instance_positions(instance_, p.data());
    const double* rest = qv_model_rest_positions(model_);
    u.resize(p.size());
    for (size_t i = 0; i < p.size(); ++i) u[i] = p[i] - rest[i];
  }
  void energies(double& kinetic, double& elastic) const override { qv_instance_energies(instance_, &kinetic, &elastic); }
  double timeStep() const override { return config_.time_step; }
  int r() const { return info_.r; }
  int indefinite() const { return indefinite_; }

private:
  qv_model* model_ = nullptr;
  qv_model_info info_{};
  qv_instance_config config_{};
  qv_instance* instance_ = nullptr;
  int indefinite_ = 0;
};

// The tet mesh stored in the model: rest shape and tets, for selection and the .vtu frames.
TetMesh modelMesh(const std::string& path) {
  const std::string bytes = readFileBytes(path);
  ModelView view;
  std::string error;
  if (!parseModel(bytes.data(), bytes.size(), view, error)) throw std::runtime_error(path + ": " + error);
  TetMesh mesh;
  for (uint32_t v = 0; v < view.info.vertexCount; ++v)
    mesh.vertices.emplace_back(view.restPositions[3 * v], view.restPositions[3 * v + 1], view.restPositions[3 * v + 2]);
  if (view.tets)
    for (uint32_t t = 0; t < view.info.tetCount; ++t)
      mesh.tets.push_back({int(view.tets[4 * t]), int(view.tets[4 * t + 1]), int(view.tets[4 * t + 2]), int(view.tets[4 * t + 3])});
  mesh.tetRegion.assign(mesh.tets.size(), 0);
  return mesh;
}

} // namespace

int simulateModel(const std::string& path, const std::string& integrator, const std::string& elasticity,
                  const SimOptions& o) {
  RuntimeTarget target(path, integrator, elasticity, o);
  const ScenarioResult result = runScenario(target, modelMesh(path), o);
  double total = 0;
  for (double us : result.stepMicros) total += us;
  const double median = percentile(result.stepMicros, 0.5), p99 = percentile(result.stepMicros, 0.99);
  if (o.json) {
    nlohmann::ordered_json j;
    j["r"] = target.r();
    j["steps"] = o.steps;
    j["time_step_s"] = target.timeStep();
    j["integrator"] = integrator;
    j["elasticity"] = elasticity;
    j["step_us_median"] = median;
    j["step_us_p99"] = p99;
    j["steps_per_second"] = 1e6 * o.steps / total;
    j["resets"] = result.failedSteps;
    j["indefinite_steps"] = target.indefinite();
    std::cout << j.dump(1) << "\n";
  } else {
    std::cout << "quiver sim: " << o.steps << " steps of r = " << target.r() << ": median " << median << " us, p99 "
              << p99 << " us per step, " << static_cast<long>(1e6 * o.steps / total) << " steps per second"
              << (result.failedSteps ? ", " + std::to_string(result.failedSteps) + " resets" : std::string()) << "\n";
    if (!o.output.empty()) std::cout << "quiver sim: wrote " << o.output << ".pvd (open in ParaView) and " << o.output << ".csv\n";
  }
  return result.failedSteps > 0 ? 2 : 0;
}

} // namespace quiver::app
