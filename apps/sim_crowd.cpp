// `quiver sim MODEL --instances N`: N instances of one model, each under its own load, stepped
// together per frame (qv_instances_step) as a game steps a crowd; reports the frame time.
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <memory>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "apps/runtime_target.h"
#include "apps/support/job_pool.h"

namespace quiver::app {

namespace {

struct AlignedFree {
  void operator()(void* p) const { std::free(p); }
};

} // namespace

void CrowdOptions::addTo(CLI::App& app) {
  app.add_option("--instances", instances,
                 "Step N instances of the model together per frame (qv_instances_step), each under its own share of "
                 "the load: --force scaled by 0.5 to 1.5 across them, or with neither --force nor --gravity a pull on "
                 "the group of 2% of the model's weight turning about x from one to the next; reports frame times")
      ->check(CLI::Range(1, 1000000));
  CLI::Option* given = app.get_option("--instances");
  app.add_option("--threads", threads,
                 "With --instances, or --free --pile N (each body's own parts of each world step and the contact "
                 "solve's islands, qv_world_set_jobs): jobs on this many threads (the caller's included)")
      ->capture_default_str()
      ->check(CLI::Range(1, 256));
  app.add_flag("--one-by-one", oneByOne, "With --instances: qv_instance_step on each instead, to compare")->needs(given);
}

int simulateCrowd(const std::string& path, const SimOptions& o, const CrowdOptions& c) {
  const std::vector<double> none{0, 0, 0};
  if (o.drag != none || o.twist != 0) throw std::runtime_error("--instances takes --force and --gravity loads, not --drag or --twist");
  if (o.step.freeFlight) throw std::runtime_error("--instances steps pinned instances; flying ones go in a world (--free --pile)");
  o.flight.check(false);  // --pile and the other flight options need --free
  if (o.step.maxSubsteps != 0) throw std::runtime_error("--max-substeps is for flying instances, which --instances does not step");
  if (!o.output.empty()) throw std::runtime_error("--instances writes no frames: leave out -o");
  const RuntimeModel model(path);
  const TetMesh mesh = model.mesh();
  const std::vector<int> group = selectGroup(mesh, o.group);
  const int n = c.instances;
  std::vector<std::unique_ptr<RuntimeInstance>> owned;
  std::vector<qv_instance*> instances;
  const qv_instance_config config = instanceConfig(model.get(), o.step);
  for (int k = 0; k < n; ++k) {
    owned.push_back(std::make_unique<RuntimeInstance>(model, config));
    instances.push_back(owned.back()->get());
    if (k == 0) warnAboveStableStep(*owned.back());
    if (o.gravity) {
      const double g[3] = {0, 0, -kGravity};
      qv_instance_set_gravity(instances.back(), g);
    }
  }
  // Instance k's force on each vertex of the group.
  std::vector<double> share(3 * static_cast<size_t>(n));
  for (int k = 0; k < n; ++k) {
    const double scale = 0.5 + (n > 1 ? static_cast<double>(k) / (n - 1) : 0.5);
    double total[3] = {o.force[0], o.force[1], o.force[2]};
    if (std::vector<double>(total, total + 3) == none && !o.gravity) {
      const double angle = 2 * M_PI * k / n, weight = model.info().total_mass * kGravity;
      total[1] = 0.02 * weight * std::cos(angle);
      total[2] = 0.02 * weight * std::sin(angle);
    }
    for (int a = 0; a < 3; ++a) share[3 * k + a] = scale * total[a] / group.size();
  }
  JobPool pool(c.oneByOne ? 1 : c.threads);
  const qv_job_runner runner = pool.runner();
  const size_t bytes = qv_instances_step_scratch_size(model.get(), pool.threads());
  std::unique_ptr<void, AlignedFree> scratch(std::aligned_alloc(64, (bytes + 63) / 64 * 64));
  std::vector<qv_step_status> statuses(n);
  std::vector<double> frameMs;
  long resets = 0, minimized = 0;
  for (int step = 0; step < o.steps; ++step) {
    if (step < o.holdSteps)
      for (int k = 0; k < n; ++k)
        for (int v : group) qv_instance_add_vertex_force(instances[k], v, &share[3 * k]);
    const auto start = std::chrono::steady_clock::now();
    if (c.oneByOne) {
      for (int k = 0; k < n; ++k) statuses[k] = qv_instance_step(instances[k]);
    } else if (qv_instances_step(instances.data(), n, pool.threads() > 1 ? &runner : nullptr, scratch.get(), bytes,
                                 statuses.data()) != QV_OK) {
      throw std::runtime_error("qv_instances_step refused its arguments");
    }
    frameMs.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
    for (qv_step_status s : statuses) resets += s == QV_STEP_RESET;
    for (qv_instance* s : instances) {
      qv_step_report report;
      qv_instance_last_step(s, &report);
      minimized += report.minimized;
    }
  }
  const double median = percentile(frameMs, 0.5), p99 = percentile(frameMs, 0.99);
  if (o.json) {
    nlohmann::ordered_json j;
    j["r"] = model.info().r;
    j["instances"] = n;
    j["threads"] = pool.threads();
    j["stepping"] = c.oneByOne ? "one by one" : "together";
    j["steps"] = o.steps;
    j["integrator"] = qv_integrator_name(config.integrator);
    j["elasticity"] = qv_elasticity_name(config.elasticity);
    j["solver"] = qv_solver_name(config.solver);
    j["frame_ms_median"] = median;
    j["frame_ms_p99"] = p99;
    j["instance_step_us_median"] = 1e3 * median / n;
    j["resets"] = resets;
    j["minimized_steps"] = minimized;  // fixed Newton steps the minimiser took
    std::cout << j.dump(1) << "\n";
  } else {
    std::cout << "quiver sim: " << n << " instances of r = " << model.info().r << ", " << o.steps << " frames "
              << (c.oneByOne ? "one by one" : "together") << " on " << pool.threads() << " thread(s): median " << median
              << " ms, p99 " << p99 << " ms per frame" << (resets ? ", " + std::to_string(resets) + " resets" : std::string())
              << "\n";
  }
  if (resets > 0)
    std::cerr << "quiver sim: warning: the instances' states went non-finite " << resets
              << " times and the runtime reset them to rest (exit code 2): the load is too large for this model or "
                 "this time step\n";
  return resets > 0 ? 2 : 0;
}

} // namespace quiver::app
