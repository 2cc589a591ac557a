#include "apps/support/step_settings.h"

#include <stdexcept>
#include <vector>

namespace quiver::app {

namespace {

// An option whose values are the names a runtime table gives, "name (description)" in --help.
template <class Enum>
CLI::Option* addChoice(CLI::App& app, const std::string& flag, Enum& target, int count, const char* (*name)(Enum),
                       const char* (*description)(Enum), qv_result (*fromName)(const char*, Enum*)) {
  std::vector<std::string> names;
  std::string help;
  for (int i = 0; i < count; ++i) {
    names.push_back(name(Enum(i)));
    help += std::string(i == 0 ? "" : i + 1 == count ? " or " : ", ") + name(Enum(i)) + " (" + description(Enum(i)) + ")";
  }
  return app
      .add_option_function<std::string>(
          flag, [&target, fromName](const std::string& value) { fromName(value.c_str(), &target); }, help)
      ->default_str(name(target))
      ->check(CLI::IsMember(names));
}

} // namespace

bool StepSettings::operator==(const StepSettings& o) const {
  return integrator == o.integrator && elasticity == o.elasticity && timeStep == o.timeStep && newton == o.newton &&
         solver == o.solver && alpha == o.alpha && beta == o.beta && freeFlight == o.freeFlight &&
         softContacts == o.softContacts && maxSubsteps == o.maxSubsteps;
}

qv_instance_config instanceConfig(const qv_model* model, const StepSettings& s) {
  qv_instance_config c;
  qv_instance_config_init(&c, model);
  c.integrator = s.integrator;
  c.elasticity = s.elasticity;
  if (s.timeStep > 0) c.time_step = s.timeStep;
  if (s.newton != 0) c.newton_iterations = s.newton;
  c.solver = s.solver;
  if (s.alpha >= 0) c.rayleigh_alpha = s.alpha;
  if (s.beta >= 0) c.rayleigh_beta = s.beta;
  c.free_flight = s.freeFlight ? 1 : 0;
  c.soft_contacts = s.softContacts ? 1 : 0;
  if (s.maxSubsteps != 0) c.max_substeps = s.maxSubsteps;
  return c;
}

CLI::Option* addIntegratorOption(CLI::App& app, qv_integrator& integrator) {
  return addChoice(app, "--integrator", integrator, QV_INTEGRATOR_COUNT, qv_integrator_name, qv_integrator_description,
                   qv_integrator_from_name);
}

CLI::Option* addElasticityOption(CLI::App& app, qv_elasticity& elasticity) {
  return addChoice(app, "--elasticity", elasticity, QV_ELASTICITY_COUNT, qv_elasticity_name, qv_elasticity_description,
                   qv_elasticity_from_name);
}

CLI::Option* addSolverOption(CLI::App& app, qv_solver& solver) {
  return addChoice(app, "--solver", solver, QV_SOLVER_COUNT, qv_solver_name, qv_solver_description, qv_solver_from_name);
}

CLI::Option* addMaxSubstepsOption(CLI::App& app, int& maxSubsteps) {
  return app
      .add_option("--max-substeps", maxSubsteps,
                  "Free flight: the most substeps a fast spin's step is cut into, so that the body turns at most 0.75 rad "
                  "in each (1: never cut; default 16)")
      ->check(CLI::Range(1, 64));
}

void checkFlightSettings(const StepSettings& s) {
  if (!s.freeFlight && s.maxSubsteps != 0) throw std::runtime_error("--max-substeps needs --free");
}

} // namespace quiver::app
