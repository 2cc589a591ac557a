// quiver: inspect and evaluate baked runtime models (.qvr). Built on the runtime library alone:
// what it prints is what a game embedding the runtime would compute.
#include <algorithm>
#include <cmath>
#include <iostream>
#include <sstream>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "apps/sim_scenario.h"
#include "apps/support/mesh_options.h"
#include "apps/support/reduced_modes.h"
#include "apps/support/scenario_file.h"
#include "apps/support/runtime_model.h"
#include "formats/mesh/read_mesh.h"
#include "formats/model/qvr.h"
#include "formats/npy.h"
#include "quiver/quiver.h"

using nlohmann::ordered_json;

namespace {

// Section names and sizes straight from the file's table (already validated by the loader).
ordered_json sectionSizes(const std::string& bytes) {
  auto u32 = [&](size_t at) { uint32_t v; std::memcpy(&v, &bytes[at], 4); return v; };
  auto u64 = [&](size_t at) { uint64_t v; std::memcpy(&v, &bytes[at], 8); return v; };
  ordered_json out = ordered_json::object();
  const uint64_t table = u64(quiver::qvr::kTableOffsetAt);
  for (uint32_t s = 0; s < u32(quiver::qvr::kSectionCountAt); ++s) {
    const size_t entry = table + s * quiver::qvr::kSectionEntrySize;
    const uint32_t type = u32(entry + quiver::qvr::kTypeAt);
    out[quiver::qvr::sectionName(type)] = u64(entry + quiver::qvr::kSizeAt);
  }
  out["file"] = bytes.size();
  return out;
}

std::vector<double> parseQ(const std::string& text, int r) {
  std::vector<double> q;
  if (text.size() > 4 && text.substr(text.size() - 4) == ".npy") {
    quiver::NpyArray a = quiver::readNpy(text);
    q = a.data;
  } else {
    std::stringstream in(text);
    std::string item;
    while (std::getline(in, item, ',')) {
      double v = 0;
      if (!quiver::app::parseNumber(item, v)) throw std::runtime_error("--q: '" + item + "' is not a number");
      q.push_back(v);
    }
  }
  if (static_cast<int>(q.size()) != r)
    throw std::runtime_error("--q has " + std::to_string(q.size()) + " values; the model has r = " + std::to_string(r));
  for (size_t k = 0; k < q.size(); ++k)
    if (!std::isfinite(q[k])) throw std::runtime_error("--q: value " + std::to_string(k) + " is not finite");
  return q;
}

// The bake's fidelity report from the file's FIDELITY section (null when it has none): per load
// case the relative displacement error and the full solution's largest displacement as a fraction
// of the size (null: not measured), and the reduced frequencies' errors.
ordered_json fidelityOf(const quiver::ModelView& view) {
  if (!view.fidelityCaseCount && !view.fidelityFrequencyCount) return nullptr;
  const auto value = [](double x) { return std::isnan(x) ? ordered_json(nullptr) : ordered_json(x); };
  ordered_json cases = ordered_json::object();
  for (uint32_t i = 0; i < view.fidelityCaseCount; ++i) {
    const unsigned char* record = view.fidelityCases + i * quiver::qvr::kFidelityRecordSize;
    double e, largest;
    std::memcpy(&e, record + quiver::qvr::kFidelityNameSize, 8);
    std::memcpy(&largest, record + quiver::qvr::kFidelityNameSize + 8, 8);
    cases[reinterpret_cast<const char*>(record)] = {{"displacement_error", value(e)}, {"largest_displacement", value(largest)}};
  }
  return {{"cases", cases},
          {"frequency_errors", std::vector<double>(view.fidelityFrequencyErrors,
                                                   view.fidelityFrequencyErrors + view.fidelityFrequencyCount)}};
}

// A free object's rigid body from RIGID_BODY (null when the file has none): centre of mass and
// inertia tensor about it, at rest.
ordered_json rigidBodyOf(const quiver::ModelView& view) {
  if (!view.rigidBody) return nullptr;
  const double* S = view.rigidBody + 3;
  const double trace = S[0] + S[4] + S[8];
  ordered_json inertia = ordered_json::array();
  for (int a = 0; a < 3; ++a)
    inertia.push_back({(a == 0 ? trace : 0) - S[3 * a], (a == 1 ? trace : 0) - S[3 * a + 1], (a == 2 ? trace : 0) - S[3 * a + 2]});
  return {{"centre_of_mass", {view.rigidBody[0], view.rigidBody[1], view.rigidBody[2]}}, {"inertia", inertia}};
}

// `quiver info`: counts, section sizes, baked and reduced frequencies, material, damping, box.
ordered_json describeModel(const quiver::app::RuntimeModel& model) {
  const qv_model_info& mi = model.info();
  ordered_json out;
  out["r"] = mi.r;
  out["vertices"] = mi.vertex_count;
  out["tets"] = mi.tet_count;
  out["surface_triangles"] = mi.triangle_count;
  out["file_vertices"] = mi.file_vertex_count;
  out["render_vertices"] = mi.render_vertex_count;  // 0: no render mesh, the tets' surface is drawn
  out["render_triangles"] = mi.render_triangle_count;
  out["basis_precision"] = mi.basis_precision;
  const std::string bytes = quiver::readFileBytes(model.path());
  out["sections"] = sectionSizes(bytes);
  std::vector<double> hz;
  for (int i = 0; i < mi.eigenvalue_count; ++i)
    hz.push_back(std::sqrt(std::max(qv_model_eigenvalues(model.get())[i], 0.0)) / (2 * M_PI));
  out["frequencies_hz"] = hz;
  // The same modes as the reduced model has them (K~(0) in span U): how well the basis holds the baked modes.
  hz.clear();
  for (double lambda : quiver::app::reducedModes(model.get()).eigenvalues)
    hz.push_back(std::sqrt(std::max(lambda, 0.0)) / (2 * M_PI));
  out["reduced_frequencies_hz"] = hz;
  out["material"] = {{"youngs_modulus", mi.youngs_modulus}, {"poisson_ratio", mi.poisson_ratio},
                     {"density", mi.density}, {"uniform", mi.material_is_uniform != 0}};
  out["total_mass"] = mi.total_mass;
  out["damping"] = {{"rayleigh_alpha", mi.rayleigh_alpha}, {"rayleigh_beta", mi.rayleigh_beta}};
  out["time_step"] = mi.time_step;
  out["bbox"] = {{"min", {mi.bbox_min[0], mi.bbox_min[1], mi.bbox_min[2]}},
                 {"max", {mi.bbox_max[0], mi.bbox_max[1], mi.bbox_max[2]}}};
  const std::vector<double> aligned((bytes.size() + 7) / 8);
  std::memcpy(const_cast<double*>(aligned.data()), bytes.data(), bytes.size());
  quiver::ModelView view;
  std::string error;
  if (!quiver::parseModel(aligned.data(), bytes.size(), view, error)) throw std::runtime_error(error);
  out["fidelity"] = fidelityOf(view);
  out["rigid_body"] = rigidBodyOf(view);
  return out;
}

// `quiver eval`: energy, force and stiffness at q.
ordered_json evaluateModel(const quiver::app::RuntimeModel& model, const std::string& qText) {
  const int r = model.info().r;
  const std::vector<double> q = parseQ(qText, r);
  std::vector<double> scratch(qv_model_scratch_size(model.get()) / sizeof(double) + 1), force(r),
      stiffness(static_cast<size_t>(r) * r);
  double energy = 0;
  qv_model_evaluate(model.get(), q.data(), &energy, force.data(), stiffness.data(), scratch.data());
  // A finite q far beyond the model's range (the energy is quartic in it) overflows.
  if (!std::isfinite(energy) || !std::all_of(force.begin(), force.end(), [](double f) { return std::isfinite(f); }) ||
      !std::all_of(stiffness.begin(), stiffness.end(), [](double k) { return std::isfinite(k); }))
    throw std::runtime_error("--q is too large: the energy, force or stiffness there overflows a double");
  ordered_json out;
  out["energy"] = energy;
  out["force"] = force;
  std::vector<std::vector<double>> rows;
  for (int i = 0; i < r; ++i) rows.emplace_back(stiffness.begin() + i * r, stiffness.begin() + (i + 1) * r);
  out["stiffness"] = rows;
  return out;
}

} // namespace

int main(int argc, char** argv) {
  CLI::App app{"quiver: inspect and evaluate baked Quiver models (.qvr)"};
  app.require_subcommand(1);
  std::string path, qText;
  CLI::App* info = app.add_subcommand("info", "Print one JSON object describing MODEL.qvr");
  info->add_option("model", path, "Model file (.qvr)")->required();
  CLI::App* eval = app.add_subcommand("eval", "Print the reduced energy, force and stiffness at q as JSON");
  eval->add_option("model", path, "Model file (.qvr)")->required();
  eval->add_option("--q", qText, "Reduced coordinates: r comma-separated numbers, or FILE.npy")->required();
  CLI::App* sim = app.add_subcommand("sim", "Run a scripted scenario; write a .vtu series (.pvd), a CSV and timings");
  quiver::app::SimOptions simOptions;
  sim->add_option("model", path, "Model file (.qvr)")->required();
  simOptions.addTo(*sim);
  quiver::app::addIntegratorOption(*sim, simOptions.step.integrator);
  quiver::app::addElasticityOption(*sim, simOptions.step.elasticity);
  quiver::app::addSolverOption(*sim, simOptions.step.solver);
  quiver::app::CrowdOptions crowd;
  crowd.addTo(*sim);
  CLI::App* render = app.add_subcommand("render", "Draw MODEL.qvr without a display: rest, after (or during) a scenario, or its modes; PNG, GIF or image sequence");
  quiver::app::RenderOptions renderOptions;
  render->add_option("model", path, "Model file (.qvr)")->required();
  renderOptions.addTo(*render);
  CLI::App* fullSpace = app.add_subcommand("full", "Run the same scenarios on the full-space StVK reference simulator");
  quiver::app::MeshOptions fullMesh;
  quiver::app::FixedVertexOptions fullFixed;
  quiver::app::FullSpaceOptions fullOptions;
  quiver::app::SimOptions fullSim;
  fullMesh.addTo(*fullSpace);
  fullFixed.addTo(*fullSpace);
  fullSim.addTo(*fullSpace);
  fullSpace->add_option("--solver", fullOptions.solver,
                        "Sparse solver: llt, ldlt (Eigen Simplicial), cg (incomplete Cholesky), lu (SparseLU)")
      ->capture_default_str()
      ->check(CLI::IsMember({"llt", "ldlt", "cg", "lu"}));
  quiver::app::addElasticityOption(*fullSpace, fullSim.step.elasticity);
  fullSpace->add_option("--E", fullOptions.material.youngsModulus, "Young's modulus in Pa; overrides the mesh file's");
  fullSpace->add_option("--nu", fullOptions.material.poissonRatio, "Poisson ratio; overrides the mesh file's");
  fullSpace->add_option("--density", fullOptions.material.density, "Density in kg/m^3; overrides the mesh file's");
  fullSpace->add_option("--final-npy", fullOptions.finalNpy, "Save the final displacement (3N, file vertex order) as .npy");
  const auto scenarioFiles = [](const std::vector<std::string>& args) {
    return quiver::app::expandScenarioFiles(args, quiver::app::SimOptions::checkScenarioOption);
  };
  return quiver::app::runTool("quiver", app, argc, argv, [&] {
    if (*fullSpace) {
      quiver::CheckedMesh mesh = fullMesh.load("quiver");
      const std::vector<int> fixed = fullFixed.select(mesh);
      return quiver::app::simulateFullSpace(mesh.mesh, mesh.fileVertex, mesh.loadedVertex.size(), fixed, fullOptions,
                                            fullSim);
    }
    if (*render) return quiver::app::renderModel(path, renderOptions);
    if (*sim && crowd.instances > 0) return quiver::app::simulateCrowd(path, simOptions, crowd);
    if (*sim && crowd.threads > 1 && simOptions.flight.pile <= 1) throw std::runtime_error("--threads needs --instances or --pile N");
    simOptions.flight.threads = crowd.threads;
    if (*sim) return quiver::app::simulateModel(path, simOptions);
    const quiver::app::RuntimeModel model(path);
    const ordered_json out = *info ? describeModel(model) : evaluateModel(model, qText);
    // Full precision: every double printed reads back exactly (nlohmann prints shortest round-trip form).
    std::cout << out.dump(1) << "\n";
    return 0;
  }, scenarioFiles);
}
