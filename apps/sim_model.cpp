// `quiver sim`: the scenario on the runtime library, as a game would drive it.
#include <algorithm>
#include <cmath>
#include <iostream>

#include <nlohmann/json.hpp>

#include "apps/runtime_target.h"

namespace quiver::app {

int simulateModel(const std::string& path, const SimOptions& o) {
  const RuntimeModel model(path);
  RuntimeTarget target(model, o.step);
  const ScenarioResult result = runScenario(target, model.mesh(), o);
  double total = 0;
  for (double us : result.stepMicros) total += us;
  const double median = percentile(result.stepMicros, 0.5), p99 = percentile(result.stepMicros, 0.99);
  if (o.json) {
    nlohmann::ordered_json j;
    j["r"] = model.info().r;
    j["steps"] = o.steps;
    j["time_step_s"] = target.timeStep();
    j["integrator"] = qv_integrator_name(o.step.integrator);
    j["elasticity"] = qv_elasticity_name(o.step.elasticity);
    j["solver"] = qv_solver_name(target.instance().config().solver);
    j["step_us_median"] = median;
    j["step_us_p99"] = p99;
    j["steps_per_second"] = 1e6 * o.steps / total;
    j["resets"] = result.failedSteps;
    j["indefinite_steps"] = target.indefiniteSteps();
    j["newton_iterations_mean"] = static_cast<double>(result.newtonIterations) / o.steps;
    j["held_back_steps"] = target.heldBackSteps();
    j["minimized_steps"] = target.minimizedSteps();
    j["energy_removed_J"] = target.energyRemoved();
    j["lowest_elastic_J"] = result.lowestElastic;
    qv_rigid_state flight;
    if (qv_instance_get_rigid_state(target.instance().get(), &flight) == QV_OK) {
      const double* v = flight.linear_velocity;
      j["final_center"] = {flight.position[0], flight.position[1], flight.position[2]};  // world centre of mass, m
      j["final_speed_mps"] = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
      j["max_penetration_m"] = target.maxPenetration();
      const FlightWorld& bodies = *target.flight();
      if (bodies.bodyCount() > 1) {  // --pile: every body's centre and the fastest of them
        double fastest = 0;
        nlohmann::json centres = nlohmann::json::array();
        for (int k = 0; k < bodies.bodyCount(); ++k) {
          qv_rigid_state s;
          qv_instance_get_rigid_state(bodies.body(k).get(), &s);
          centres.push_back({s.position[0], s.position[1], s.position[2]});
          fastest = std::max(fastest, std::sqrt(s.linear_velocity[0] * s.linear_velocity[0] + s.linear_velocity[1] * s.linear_velocity[1] +
                                                s.linear_velocity[2] * s.linear_velocity[2]));
        }
        j["bodies"] = bodies.bodyCount();
        j["threads"] = o.flight.threads;
        j["final_centers"] = centres;
        j["max_final_speed_mps"] = fastest;
        j["asleep_at_end"] = bodies.asleepCount();
      }
    }
    std::cout << j.dump(1) << "\n";
  } else {
    std::cout << "quiver sim: " << o.steps << " steps of r = " << model.info().r << ": median " << median << " us, p99 "
              << p99 << " us per step, " << static_cast<long>(1e6 * o.steps / total) << " steps per second"
              << (result.failedSteps ? ", " + std::to_string(result.failedSteps) + " resets" : std::string()) << "\n";
    if (!o.output.empty())
      std::cout << "quiver sim: wrote " << o.output << ".pvd (open in ParaView)"
                << (model.info().render_vertex_count ? ", " + o.output + "_render.pvd (the render mesh)" : std::string()) << " and "
                << o.output << ".csv\n";
  }
  if (const std::string warning = negativeEnergyWarning(result); !warning.empty())
    std::cerr << "quiver sim: warning: " << warning << "\n";
  if (result.failedSteps > 0) {
    std::cerr << "quiver sim: warning: the state went non-finite " << result.failedSteps
              << " times and the runtime reset it to rest (exit code 2): the load is too large for this model or "
                 "this time step\n";
    return 2;
  }
  return 0;
}

} // namespace quiver::app
