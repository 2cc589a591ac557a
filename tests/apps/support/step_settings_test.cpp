// The tools' one mapping from names to the runtime's choices, and the one config builder.
#include <gtest/gtest.h>

#include "apps/support/step_settings.h"

using namespace quiver::app;

TEST(StepSettings, EveryRuntimeChoiceHasANameTheOptionsAccept) {
  for (int i = 0; i < QV_INTEGRATOR_COUNT; ++i) {
    CLI::App app;
    qv_integrator chosen = QV_INTEGRATOR_IMPLICIT_NEWMARK;
    addIntegratorOption(app, chosen);
    const std::string name = qv_integrator_name(qv_integrator(i));
    app.parse(std::vector<std::string>{"--integrator=" + name});
    EXPECT_EQ(chosen, qv_integrator(i)) << name;
    EXPECT_NE(app.help().find(name), std::string::npos);
  }
  for (int i = 0; i < QV_ELASTICITY_COUNT; ++i) {
    CLI::App app;
    qv_elasticity chosen = QV_ELASTICITY_STVK;
    addElasticityOption(app, chosen);
    const std::string name = qv_elasticity_name(qv_elasticity(i));
    app.parse(std::vector<std::string>{"--elasticity=" + name});
    EXPECT_EQ(chosen, qv_elasticity(i)) << name;
  }
  // The names the documentation and scripts use.
  EXPECT_STREQ(qv_integrator_name(QV_INTEGRATOR_BACKWARD_EULER), "euler");
  EXPECT_STREQ(qv_elasticity_name(QV_ELASTICITY_MODAL_WARPING), "warping");
  EXPECT_EQ(qv_integrator_name(QV_INTEGRATOR_COUNT), nullptr);
}

TEST(StepSettings, AnUnknownNameIsRefusedAndTheTargetKept) {
  CLI::App app;
  qv_integrator chosen = QV_INTEGRATOR_CENTRAL_DIFFERENCES;
  addIntegratorOption(app, chosen);
  try {
    app.parse(std::vector<std::string>{"--integrator=verlet"});
    FAIL() << "verlet was accepted";
  } catch (const CLI::ValidationError& e) {
    EXPECT_NE(std::string(e.what()).find("verlet"), std::string::npos) << e.what();
  }
  EXPECT_EQ(chosen, QV_INTEGRATOR_CENTRAL_DIFFERENCES);
  qv_integrator out = QV_INTEGRATOR_IMPLICIT_NEWMARK;
  EXPECT_EQ(qv_integrator_from_name("Newmark", &out), QV_ERROR_INVALID_ARGUMENT) << "names are exact";
  EXPECT_EQ(qv_integrator_from_name(nullptr, &out), QV_ERROR_INVALID_ARGUMENT);
}

TEST(StepSettings, TheConfigIsTheDefaultsOverriddenWhereAsked) {
  qv_instance_config defaults;
  qv_instance_config_init(&defaults, nullptr);
  const qv_instance_config same = instanceConfig(nullptr, StepSettings{});
  EXPECT_EQ(same.integrator, defaults.integrator);
  EXPECT_EQ(same.elasticity, defaults.elasticity);
  EXPECT_EQ(same.time_step, defaults.time_step);
  EXPECT_EQ(same.newton_iterations, defaults.newton_iterations) << "0: the runtime's default";
  EXPECT_EQ(same.solver, QV_SOLVER_MINIMIZE);
  EXPECT_EQ(same.rayleigh_alpha, defaults.rayleigh_alpha);
  EXPECT_EQ(same.rayleigh_beta, defaults.rayleigh_beta);
  EXPECT_EQ(same.max_constraints, defaults.max_constraints);

  StepSettings s{QV_INTEGRATOR_BACKWARD_EULER, QV_ELASTICITY_LINEAR, 0.002, 4, QV_SOLVER_NEWTON, 0.5, 0.01};
  const qv_instance_config c = instanceConfig(nullptr, s);
  EXPECT_EQ(c.integrator, QV_INTEGRATOR_BACKWARD_EULER);
  EXPECT_EQ(c.elasticity, QV_ELASTICITY_LINEAR);
  EXPECT_EQ(c.time_step, 0.002);
  EXPECT_EQ(c.newton_iterations, 4);
  EXPECT_EQ(c.solver, QV_SOLVER_NEWTON);
  EXPECT_EQ(c.rayleigh_alpha, 0.5);
  EXPECT_EQ(c.rayleigh_beta, 0.01);
  s.alpha = 0;  // zero is a value, not "the default"
  EXPECT_EQ(instanceConfig(nullptr, s).rayleigh_alpha, 0.0);
}
