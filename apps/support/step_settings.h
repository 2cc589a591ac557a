#pragma once
// How the tools step a runtime instance, and the one place in apps/ that maps the runtime's
// choices to names (taken from the runtime's own tables: qv_integrator_name, qv_elasticity_name)
// and builds a qv_instance_config: quiver sim, quiver render and the viewer all come here.
#include <string>

#include <CLI/CLI.hpp>

#include "quiver/quiver.h"

namespace quiver::app {

struct StepSettings {
  qv_integrator integrator = QV_INTEGRATOR_IMPLICIT_NEWMARK;
  qv_elasticity elasticity = QV_ELASTICITY_STVK;
  double timeStep = 0;           // s; 0: the model's
  int newton = 0;                // Newton iterations per implicit step (the most, or exactly: qv_solver); 0: the runtime's default
  qv_solver solver = QV_SOLVER_MINIMIZE;
  double alpha = -1, beta = -1;  // Rayleigh damping; negative: the model's
  bool freeFlight = false;       // the object flies (a model baked free): qv_instance_config::free_flight
  bool softContacts = false;     // its contacts hold the deformed surface: qv_instance_config::soft_contacts
  int maxSubsteps = 0;           // in flight, the most substeps of a fast spin's step: qv_instance_config::max_substeps; 0: the runtime's

  bool operator==(const StepSettings& o) const;
};

// The gravity the tools apply (--gravity, the viewer's checkbox): m/s^2, along -z.
inline constexpr double kGravity = QV_STANDARD_GRAVITY;

// The model's defaults, overridden where `settings` says.
qv_instance_config instanceConfig(const qv_model* model, const StepSettings& settings);

// --integrator, --elasticity and --solver: a value is one of the runtime's names, stored as the enum.
CLI::Option* addIntegratorOption(CLI::App& app, qv_integrator& integrator);
CLI::Option* addElasticityOption(CLI::App& app, qv_elasticity& elasticity);
CLI::Option* addSolverOption(CLI::App& app, qv_solver& solver);
// --max-substeps (StepSettings::maxSubsteps), which only flight takes: checkFlightSettings().
CLI::Option* addMaxSubstepsOption(CLI::App& app, int& maxSubsteps);
// Refuses, saying why, what only flight takes without --free (the runtime would ignore it).
void checkFlightSettings(const StepSettings& settings);

} // namespace quiver::app
