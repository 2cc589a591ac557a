#include "apps/sim_scenario.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "common/vertex_selector.h"
#include "formats/atomic_file.h"
#include "formats/mesh/read_mesh.h"
#include "formats/mesh/write_mesh.h"
#include "formats/model/qvr.h"
#include "quiver/quiver.h"

namespace quiver::app {

void SimOptions::addTo(CLI::App& app) {
  app.add_option("--steps", steps, "Steps to simulate")->capture_default_str()->check(CLI::PositiveNumber);
  app.add_option("--hold", holdSteps, "Steps the load acts before it is released")->capture_default_str();
  app.add_option("--group", group, "Loaded vertices, a selector such as \"x>max-1e-6\" (mesh units)")->capture_default_str();
  app.add_option("--force", force, "Pull: total force on the group, N, as fx,fy,fz")->delimiter(',')->expected(3);
  app.add_option("--drag", drag, "Drag: move the group's targets by dx,dy,dz (m) over the hold")->delimiter(',')->expected(3);
  app.add_option("--twist", twist, "Drag: rotate the group's targets by this many degrees about x over the hold");
  app.add_option("--stiffness", stiffness, "Drag: penalty spring per vertex, N/m")->capture_default_str();
  app.add_flag("--gravity", gravity, "Gravity, 9.81 m/s^2 along -z");
  app.add_option("--integrator", integrator, "newmark, euler or central")
      ->capture_default_str()
      ->check(CLI::IsMember({"newmark", "euler", "central"}));
  app.add_option("--dt", timeStep, "Time step, s (default: the model's)")->check(CLI::PositiveNumber);
  app.add_option("--newton", newton, "Newton iterations per implicit step")->capture_default_str();
  app.add_option("--alpha", alpha, "Mass-proportional damping, 1/s (default: the model's)");
  app.add_option("--beta", beta, "Stiffness-proportional damping, s (default: the model's)");
  app.add_option("-o,--output", output, "Write NAME.pvd with NAME_NNNN.vtu frames and NAME.csv");
  app.add_option("--every", every, "Write every k-th step")->capture_default_str()->check(CLI::PositiveNumber);
  app.add_flag("--json", json, "Print one JSON summary");
}

namespace {

struct Model {
  qv_model* model = nullptr;
  ~Model() { qv_model_destroy(model); }
};
struct Instance {
  qv_instance* instance = nullptr;
  ~Instance() { qv_instance_destroy(instance); }
};

// The tet mesh stored in the model (for the .vtu frames and for selecting vertices).
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

double percentile(std::vector<double> values, double p) {
  std::sort(values.begin(), values.end());
  return values[std::min(values.size() - 1, static_cast<size_t>(p * (values.size() - 1) + 0.5))];
}

} // namespace

int runScenario(const std::string& path, const SimOptions& o) {
  Model m;
  char message[1024] = "";
  if (qv_model_load_file(path.c_str(), nullptr, nullptr, &m.model, message, sizeof message) != QV_OK)
    throw std::runtime_error(message);
  qv_model_info info;
  qv_model_get_info(m.model, &info);
  const TetMesh mesh = modelMesh(path);
  std::vector<int> group;
  try {
    group = VertexSelector(o.group).select(mesh);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(std::string("--group: ") + e.what());
  }
  if (group.empty()) throw std::runtime_error("--group '" + o.group + "' selects no vertex");
  const bool dragMode = o.twist != 0 || o.drag != std::vector<double>{0, 0, 0};

  qv_instance_config config;
  qv_instance_config_init(&config, m.model);
  config.integrator = o.integrator == "euler"     ? QV_INTEGRATOR_BACKWARD_EULER
                      : o.integrator == "central" ? QV_INTEGRATOR_CENTRAL_DIFFERENCES
                                                  : QV_INTEGRATOR_IMPLICIT_NEWMARK;
  if (o.timeStep > 0) config.time_step = o.timeStep;
  config.newton_iterations = o.newton;
  if (o.alpha >= 0) config.rayleigh_alpha = o.alpha;
  if (o.beta >= 0) config.rayleigh_beta = o.beta;
  Instance inst;
  if (qv_instance_create(m.model, &config, nullptr, &inst.instance) != QV_OK)
    throw std::runtime_error("invalid simulation settings (time step, Newton iterations, damping)");
  if (config.integrator == QV_INTEGRATOR_CENTRAL_DIFFERENCES && config.time_step > qv_instance_stable_time_step(inst.instance))
    std::cerr << "quiver: warning: --dt " << config.time_step << " s is above central differences' stable step "
              << qv_instance_stable_time_step(inst.instance) << " s\n";
  if (o.gravity) {
    const double g[3] = {0, 0, -9.81};
    qv_instance_set_gravity(inst.instance, g);
  }

  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (int v : group) centre += mesh.vertices[v];
  centre /= static_cast<double>(group.size());
  std::vector<double> targets(3 * group.size());
  std::vector<float> positions(3 * static_cast<size_t>(info.vertex_count));
  std::vector<double> stepMicros;
  std::ostringstream csv;
  csv << "step,time_s,kinetic_J,elastic_J,step_us,status\n";
  std::string pvd = "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n<Collection>\n";
  int resets = 0, indefinite = 0;
  if (!o.output.empty() && std::filesystem::path(o.output).has_parent_path())
    std::filesystem::create_directories(std::filesystem::path(o.output).parent_path());
  const std::string stem = std::filesystem::path(o.output).filename().string();
  for (int step = 0; step < o.steps; ++step) {
    const bool holding = step < o.holdSteps;
    if (holding && dragMode) {
      const double s = static_cast<double>(step + 1) / o.holdSteps, angle = s * o.twist * M_PI / 180;
      const Eigen::Matrix3d R = Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitX()).toRotationMatrix();
      for (size_t k = 0; k < group.size(); ++k) {
        const Eigen::Vector3d x = centre + R * (mesh.vertices[group[k]] - centre) + s * Eigen::Vector3d(o.drag.data());
        for (int c = 0; c < 3; ++c) targets[3 * k + c] = x[c];
      }
      qv_instance_set_constraint(inst.instance, 0, group.data(), static_cast<int>(group.size()), targets.data(), o.stiffness);
    } else if (holding) {
      const double share[3] = {o.force[0] / group.size(), o.force[1] / group.size(), o.force[2] / group.size()};
      for (int v : group) qv_instance_add_vertex_force(inst.instance, v, share);
    } else if (step == o.holdSteps && dragMode) {
      qv_instance_clear_constraint(inst.instance, 0);
    }
    const auto start = std::chrono::steady_clock::now();
    const qv_step_status status = qv_instance_step(inst.instance);
    stepMicros.push_back(std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start).count());
    resets += status == QV_STEP_RESET;
    indefinite += status == QV_STEP_INDEFINITE;
    double kinetic = 0, elastic = 0;
    qv_instance_energies(inst.instance, &kinetic, &elastic);
    csv << step + 1 << "," << (step + 1) * config.time_step << "," << kinetic << "," << elastic << ","
        << stepMicros.back() << "," << status << "\n";
    if (!o.output.empty() && (step + 1) % o.every == 0) {
      qv_instance_positions(inst.instance, positions.data());
      PointField u{"displacement", {}};
      for (int v = 0; v < info.vertex_count; ++v)
        u.values.emplace_back(positions[3 * v] - mesh.vertices[v].x(), positions[3 * v + 1] - mesh.vertices[v].y(),
                              positions[3 * v + 2] - mesh.vertices[v].z());
      char name[64];
      std::snprintf(name, sizeof name, "_%05d.vtu", step + 1);
      writeFileAtomically(o.output + name, formatVtu(mesh, {u}));
      pvd += "<DataSet timestep=\"" + std::to_string((step + 1) * config.time_step) + "\" file=\"" + stem + name + "\"/>\n";
    }
  }
  if (!o.output.empty()) {
    writeFileAtomically(o.output + ".pvd", pvd + "</Collection>\n</VTKFile>\n");
    writeFileAtomically(o.output + ".csv", csv.str());
  }
  double total = 0;
  for (double us : stepMicros) total += us;
  const double median = percentile(stepMicros, 0.5), p99 = percentile(stepMicros, 0.99);
  if (o.json) {
    nlohmann::ordered_json j;
    j["r"] = info.r;
    j["steps"] = o.steps;
    j["time_step_s"] = config.time_step;
    j["integrator"] = o.integrator;
    j["step_us_median"] = median;
    j["step_us_p99"] = p99;
    j["steps_per_second"] = 1e6 * o.steps / total;
    j["resets"] = resets;
    j["indefinite_steps"] = indefinite;
    std::cout << j.dump(1) << "\n";
  } else {
    std::cout << "quiver sim: " << o.steps << " steps of r = " << info.r << ": median " << median << " us, p99 " << p99
              << " us per step, " << static_cast<long>(1e6 * o.steps / total) << " steps per second"
              << (resets ? ", " + std::to_string(resets) + " resets" : std::string()) << "\n";
    if (!o.output.empty()) std::cout << "quiver sim: wrote " << o.output << ".pvd (open in ParaView) and " << o.output << ".csv\n";
  }
  return resets > 0 ? 2 : 0;
}

} // namespace quiver::app
