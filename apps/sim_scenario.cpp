#include "apps/sim_scenario.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <sstream>

#include <Eigen/Geometry>

#include "apps/support/mesh_options.h"
#include "common/vertex_selector.h"
#include "formats/atomic_file.h"
#include "formats/mesh/write_mesh.h"
#include "formats/xml_text.h"

namespace quiver::app {

void SimOptions::addScenarioTo(CLI::App& app) {
  app.add_option("--steps", steps, "Steps to simulate")->capture_default_str()->check(Positive);
  app.add_option("--hold", holdSteps, "Steps the load acts before it is released")->capture_default_str()->check(NonNegative);
  app.add_option("--group", group, "Loaded vertices, a selector such as \"x>max-1e-6\" (mesh units)")->capture_default_str();
  app.add_option("--force", force, "Pull: total force on the group, N, as fx,fy,fz")
      ->delimiter(',')
      ->expected(3)
      ->check(Finite);
  app.add_option("--drag", drag, "Drag: move the group's targets by dx,dy,dz (m) over the hold")
      ->delimiter(',')
      ->expected(3)
      ->check(Finite);
  app.add_option("--twist", twist, "Drag: rotate the group's targets by this many degrees over the hold")->check(Finite);
  app.add_option("--axis", axis, "Drag: the twist axis, through the group's centre")
      ->capture_default_str()
      ->check(CLI::IsMember({"x", "y", "z"}));
  app.add_option("--stiffness", stiffness, "Drag: penalty spring per vertex, N/m")->capture_default_str()->check(Positive);
  app.add_flag("--gravity", gravity, "Gravity, 9.81 m/s^2 along -z");
  app.add_flag("--free", step.freeFlight, "Fly: rigid motion with the deformation (a model baked with no fixed vertex)");
  app.add_flag("--soft-contacts", step.softContacts,
               "Free flight: contacts hold the deformed surface, which gives way where they push (soft objects rest flat)");
  addMaxSubstepsOption(app, step.maxSubsteps);
  flight.addTo(app);
  app.add_option("--dt", step.timeStep, "Time step, s")->check(TimeStep);
  app.add_option("--newton", step.newton,
                 "Newton iterations per implicit step: the most (--solver minimize, default 8; full space, default 20) "
                 "or exactly (--solver newton)")
      ->check(Positive);
  app.add_option("--alpha", step.alpha, "Mass-proportional damping, 1/s (default: the model's)")->check(NonNegative);
  app.add_option("--beta", step.beta, "Stiffness-proportional damping, s (default: the model's)")->check(NonNegative);
  app.add_option("--scenario", scenarioFile,
                 "Read scenario options from FILE, one 'name = value' per line (apps/support/scenario_file.h)");
}

std::string SimOptions::checkScenarioOption(const std::string& name, const std::string& value) {
  CLI::App app;
  SimOptions options;
  options.addScenarioTo(app);
  std::string names;
  for (const CLI::Option* option : app.get_options())
    for (const std::string& n : option->get_lnames())
      if (n != "scenario" && n != "help") names += (names.empty() ? "" : ", ") + n;
  if (name == "scenario" || name == "help" || !app.get_option_no_throw("--" + name))
    return "'" + name + "' is not a scenario option (" + names + ")";
  std::vector<std::string> token{"--" + name + "=" + value};
  try {
    app.parse(token);
  } catch (const CLI::ParseError& e) {
    return e.what();
  }
  return "";
}

void SimOptions::addTo(CLI::App& app) {
  addScenarioTo(app);
  CLI::Option* writes = app.add_option("-o,--output", output, "Write NAME.pvd with NAME_NNNNN.vtu frames and NAME.csv")
                           ->transform(OutputName({".pvd", ".csv"}));
  app.add_option("--every", every, "Write every k-th step")->capture_default_str()->check(Positive)->needs(writes);
  app.add_flag("--json", json, "Print one JSON summary");
}

bool SimOptions::hasLoad() const {
  const std::vector<double> none{0, 0, 0};
  return force != none || drag != none || twist != 0 || gravity;
}

double percentile(std::vector<double> values, double p) {
  std::sort(values.begin(), values.end());
  return values.empty() ? 0 : values[std::min(values.size() - 1, static_cast<size_t>(p * (values.size() - 1) + 0.5))];
}

std::vector<int> selectGroup(const TetMesh& mesh, const std::string& selector) {
  std::vector<int> group;
  try {
    group = VertexSelector(selector).select(mesh);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(std::string("--group: ") + e.what());
  }
  if (group.empty()) throw std::runtime_error("--group '" + selector + "' selects no vertex");
  return group;
}

std::string negativeEnergyWarning(const ScenarioResult& result) {
  if (!(result.lowestElastic < -1e-6 * result.largestEnergy)) return "";
  std::ostringstream text;
  text << "the elastic energy fell to " << result.lowestElastic << " J (step " << result.lowestElasticStep
       << "): no St.Venant-Kirchhoff energy is ever negative, so this model's is not one (a crafted or damaged "
          "file?), and its motion means nothing";
  return text.str();
}

ScenarioResult runScenario(ScenarioTarget& target, const TetMesh& mesh, const SimOptions& o,
                           const std::function<void(int)>& afterStep) {
  const std::vector<int> group = selectGroup(mesh, o.group);
  const bool dragMode = o.twist != 0 || o.drag != std::vector<double>{0, 0, 0};
  o.flight.check(o.step.freeFlight);
  checkFlightSettings(o.step);
  if (o.step.freeFlight) target.startFlight(o);
  if (o.gravity) {
    const double g[3] = {0, 0, -kGravity};
    target.setGravity(g);
  }
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (int v : group) centre += mesh.vertices[v];
  centre /= static_cast<double>(group.size());

  ScenarioResult result;
  std::vector<double> targets(3 * group.size()), u;
  std::ostringstream csv;
  csv << "step,time_s,kinetic_J,elastic_J,step_us,newton,status\n";
  std::string pvd = "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n<Collection>\n";
  const std::string stem = std::filesystem::path(o.output).filename().string();
  if (!o.output.empty() && std::filesystem::path(o.output).has_parent_path())
    std::filesystem::create_directories(std::filesystem::path(o.output).parent_path());
  const double h = target.timeStep();
  const std::vector<unsigned> renderTriangles = target.renderTriangles();
  std::string renderPvd = pvd;
  if (afterStep) afterStep(0);  // the start, set up
  for (int step = 0; step < o.steps; ++step) {
    if (step < o.holdSteps && dragMode) {
      const double s = static_cast<double>(step + 1) / o.holdSteps;
      const Eigen::Vector3d axis = Eigen::Vector3d::Unit(o.axis[0] - 'x');
      const Eigen::Matrix3d R = Eigen::AngleAxisd(s * o.twist * M_PI / 180, axis).toRotationMatrix();
      for (size_t k = 0; k < group.size(); ++k) {
        const Eigen::Vector3d x = centre + R * (mesh.vertices[group[k]] - centre) + s * Eigen::Vector3d(o.drag.data());
        for (int c = 0; c < 3; ++c) targets[3 * k + c] = x[c];
      }
      target.setSprings(group, targets, o.stiffness);
    } else if (step < o.holdSteps) {
      const double share[3] = {o.force[0] / group.size(), o.force[1] / group.size(), o.force[2] / group.size()};
      for (int v : group) target.addVertexForce(v, share);
    } else if (step == o.holdSteps && dragMode) {
      target.clearSprings();
    }
    int newton = 0;
    const auto start = std::chrono::steady_clock::now();
    const int status = target.step(newton);
    result.stepMicros.push_back(std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start).count());
    result.newtonIterations += newton;
    result.failedSteps += status != 0;
    double kinetic = 0, elastic = 0;
    target.energies(kinetic, elastic);
    if (elastic < result.lowestElastic) result.lowestElastic = elastic, result.lowestElasticStep = step + 1;
    result.largestEnergy = std::max(result.largestEnergy, kinetic + std::abs(elastic));
    csv << step + 1 << "," << (step + 1) * h << "," << kinetic << "," << elastic << "," << result.stepMicros.back() << ","
        << newton << "," << status << "\n";
    if (afterStep) afterStep(step + 1);
    if (!o.output.empty() && (step + 1) % o.every == 0)
      for (int body = 0; body < target.bodyCount(); ++body) {  // a pile: one part per body
        target.displacement(body, u);
        PointField field{"displacement", {}};
        for (int v = 0; v < mesh.vertexCount(); ++v) field.values.emplace_back(u[3 * v], u[3 * v + 1], u[3 * v + 2]);
        char name[64];
        if (target.bodyCount() == 1) {
          std::snprintf(name, sizeof name, "_%05d.vtu", step + 1);
        } else {
          std::snprintf(name, sizeof name, "_%05d_%d.vtu", step + 1, body);
        }
        writeFileAtomically(o.output + name, formatVtu(mesh, {field}));
        const std::string entry = "<DataSet timestep=\"" + std::to_string((step + 1) * h) + "\" part=\"" + std::to_string(body) + "\" file=\"";
        pvd += entry + escapeXml(stem + name) + "\"/>\n";
        if (renderTriangles.empty()) continue;
        std::vector<float> positions, normals;
        target.renderFrame(body, positions, normals);
        writeFileAtomically(o.output + "_render" + name, formatTriangleVtu(positions, renderTriangles, normals));
        renderPvd += entry + escapeXml(stem + "_render" + name) + "\"/>\n";
      }
  }
  if (!o.output.empty()) {
    writeFileAtomically(o.output + ".pvd", pvd + "</Collection>\n</VTKFile>\n");
    if (!renderTriangles.empty()) writeFileAtomically(o.output + "_render.pvd", renderPvd + "</Collection>\n</VTKFile>\n");
    writeFileAtomically(o.output + ".csv", csv.str());
  }
  return result;
}

} // namespace quiver::app
