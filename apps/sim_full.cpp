// `quiver full`: the scenario on the full-space StVK reference simulator.
#include <iostream>

#include <nlohmann/json.hpp>

#include "apps/sim_scenario.h"
#include "common/full_space_simulator.h"
#include "formats/npy.h"

namespace quiver::app {

namespace {

class FullSpaceTarget : public ScenarioTarget {
public:
  FullSpaceTarget(const TetMesh& mesh, const std::vector<Material>& perTet, const std::vector<int>& fixed,
                  const FullSpaceSettings& settings)
      : sim_(mesh, perTet, fixed, settings), timeStep_(settings.timeStep) {}
  void addVertexForce(int vertex, const double f[3]) override { sim_.addVertexForce(vertex, Eigen::Vector3d(f[0], f[1], f[2])); }
  void setGravity(const double g[3]) override { sim_.setGravity(Eigen::Vector3d(g[0], g[1], g[2])); }
  void startFlight(const SimOptions&) override {
    throw std::runtime_error("--free: the full-space reference simulates pinned objects only");
  }
  void setSprings(const std::vector<int>& vertices, const std::vector<double>& targets, double stiffness) override {
    std::vector<Eigen::Vector3d> points;
    for (size_t k = 0; k < vertices.size(); ++k) points.emplace_back(targets[3 * k], targets[3 * k + 1], targets[3 * k + 2]);
    sim_.setSprings(vertices, points, stiffness);
  }
  void clearSprings() override { sim_.clearSprings(); }
  int step(int& newton) override {
    newton = sim_.step();
    return 0;
  }
  void displacement(int, std::vector<double>& u) const override {
    const Eigen::VectorXd shown = sim_.displacement();
    u.assign(shown.data(), shown.data() + shown.size());
  }
  void energies(double& kinetic, double& elastic) const override {
    kinetic = sim_.kineticEnergy();
    elastic = sim_.elasticEnergy();
  }
  double timeStep() const override { return timeStep_; }
  const FullSpaceSimulator& simulator() const { return sim_; }

private:
  FullSpaceSimulator sim_;
  double timeStep_;
};

} // namespace

int simulateFullSpace(const TetMesh& mesh, const std::vector<int>& fileVertex, size_t fileVertexCount,
                      const std::vector<int>& fixed, const FullSpaceOptions& full, const SimOptions& o) {
  FullSpaceSettings settings;
  settings.solver = parseSparseSolver(full.solver);
  settings.elasticity = o.step.elasticity;
  if (o.step.timeStep > 0) settings.timeStep = o.step.timeStep;
  if (o.step.alpha >= 0) settings.rayleighAlpha = o.step.alpha;
  if (o.step.beta >= 0) settings.rayleighBeta = o.step.beta;
  settings.maxNewtonIterations = std::max(o.step.newton, 20);
  std::vector<Material> perTet = resolveTetMaterials(mesh, Material{}, full.material);
  for (const Material& m : perTet)
    if (std::string bad = checkMaterial(m); !bad.empty()) throw std::runtime_error(bad);
  FullSpaceTarget target(mesh, perTet, fixed, settings);
  const ScenarioResult result = runScenario(target, mesh, o);
  const Eigen::VectorXd u = target.simulator().displacement();
  if (!full.finalNpy.empty()) {
    std::vector<double> rows(3 * fileVertexCount, 0.0);
    for (size_t v = 0; v < fileVertex.size(); ++v)
      for (int c = 0; c < 3; ++c) rows[3 * fileVertex[v] + c] = u[3 * v + c];
    writeNpy(full.finalNpy, {static_cast<int64_t>(rows.size())}, rows.data());
  }
  double total = 0;
  for (double us : result.stepMicros) total += us;
  if (o.json) {
    nlohmann::ordered_json j;
    j["dofs"] = target.simulator().dofCount();
    j["solver"] = full.solver;
    j["elasticity"] = qv_elasticity_name(o.step.elasticity);
    j["steps"] = o.steps;
    j["time_step_s"] = settings.timeStep;
    j["step_ms_mean"] = 1e-3 * total / o.steps;
    j["step_ms_median"] = 1e-3 * percentile(result.stepMicros, 0.5);
    j["newton_iterations_mean"] = static_cast<double>(result.newtonIterations) / o.steps;
    j["final_displacement_norm"] = u.norm();
    j["seconds_per_simulated_second"] = 1e-6 * total / (o.steps * settings.timeStep);
    std::cout << j.dump(1) << "\n";
  } else {
    std::cout << "quiver full: " << o.steps << " steps of " << target.simulator().dofCount() << " DOFs with " << full.solver
              << ": " << 1e-3 * total / o.steps << " ms per step, "
              << static_cast<double>(result.newtonIterations) / o.steps << " Newton iterations per step\n";
    if (!o.output.empty()) std::cout << "quiver full: wrote " << o.output << ".pvd and " << o.output << ".csv\n";
  }
  return 0;
}

} // namespace quiver::app
