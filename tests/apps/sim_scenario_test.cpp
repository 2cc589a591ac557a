// runScenario against a recording target: which loads reach the simulator at which step, worked
// out by hand from the scenario's definition, and what -o writes.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>

#include "apps/sim_scenario.h"
#include "common/box_mesh.h"
#include "tests/support/test_support.h"

namespace fs = std::filesystem;
using namespace quiver::app;

namespace {

struct Recorder : ScenarioTarget {
  struct Step {
    std::vector<std::pair<int, Eigen::Vector3d>> forces;
    bool springs = false;
    std::vector<double> targets;
    double stiffness = 0;
  };
  std::vector<Step> steps{1};
  Eigen::Vector3d gravity = Eigen::Vector3d::Zero();
  int failAt = -1;

  void addVertexForce(int v, const double f[3]) override { steps.back().forces.emplace_back(v, Eigen::Vector3d(f)); }
  void setGravity(const double g[3]) override { gravity = Eigen::Vector3d(g); }
  void startFlight(const SimOptions& o) override { flight = Eigen::Vector3d(o.flight.velocity.data()); }
  Eigen::Vector3d flight = Eigen::Vector3d::Constant(-1);  // the velocity it was started with
  void setSprings(const std::vector<int>&, const std::vector<double>& t, double k) override {
    steps.back().springs = true;
    steps.back().targets = t;
    steps.back().stiffness = k;
  }
  void clearSprings() override { steps.back().springs = false; }
  int step(int& newton) override {
    newton = 2;
    const bool failed = static_cast<int>(steps.size()) - 1 == failAt;
    const bool springs = steps.back().springs;
    steps.emplace_back();
    steps.back().springs = springs;  // springs persist until cleared
    return failed ? 1 : 0;
  }
  void displacement(int, std::vector<double>& u) const override { u.assign(3 * 27, 0.25); }
  std::map<int, double> elasticAfter;  // steps taken -> elastic energy (else 2 J)
  void energies(double& k, double& e) const override {
    const auto it = elasticAfter.find(static_cast<int>(steps.size()) - 1);
    k = 1, e = it == elasticAfter.end() ? 2 : it->second;
  }
  double timeStep() const override { return 0.5; }
};

// A 2 x 2 x 2 box of unit cells: the group x > max - 1e-6 is the nine vertices at x = 2, centred at (2, 1, 1).
quiver::TetMesh box() { return quiver::makeBoxMesh(Eigen::Vector3d(2, 2, 2), {2, 2, 2}); }

} // namespace

TEST(Scenario, APullSpreadsTheForceOverTheGroupWhileHeld) {
  SimOptions o;
  o.steps = 5;
  o.holdSteps = 3;
  o.force = {9, 0, -18};
  Recorder target;
  const ScenarioResult result = runScenario(target, box(), o);
  ASSERT_EQ(result.stepMicros.size(), 5u);
  EXPECT_EQ(result.newtonIterations, 10);
  EXPECT_EQ(target.gravity, Eigen::Vector3d::Zero());
  for (int s = 0; s < 5; ++s) {
    const auto& forces = target.steps[s].forces;
    if (s >= 3) {
      EXPECT_TRUE(forces.empty()) << "step " << s << ": released";
      continue;
    }
    ASSERT_EQ(forces.size(), 9u) << "step " << s;
    for (const auto& [vertex, f] : forces) EXPECT_TRUE(f.isApprox(Eigen::Vector3d(1, 0, -2))) << f.transpose();
  }
}

TEST(Scenario, ADragMovesAndTurnsTheTargetsThenReleases) {
  SimOptions o;
  o.steps = 6;
  o.holdSteps = 4;
  o.drag = {0, 0, 0.4};
  o.twist = 90;
  o.axis = "x";
  o.stiffness = 123;
  o.gravity = true;
  Recorder target;
  const quiver::TetMesh mesh = box();
  runScenario(target, mesh, o);
  EXPECT_TRUE(target.gravity.isApprox(Eigen::Vector3d(0, 0, -9.81)));
  const std::vector<int> group = selectGroup(mesh, o.group);
  ASSERT_EQ(group.size(), 9u);
  // At the last held step (s = 1) a vertex at (2, y, z) sits at the centre plus its offset turned
  // 90 degrees about x, (y - 1, z - 1) -> (-(z - 1), y - 1), plus the whole drag.
  const Recorder::Step& last = target.steps[3];
  ASSERT_TRUE(last.springs);
  EXPECT_EQ(last.stiffness, 123);
  for (size_t k = 0; k < group.size(); ++k) {
    const Eigen::Vector3d x = mesh.vertices[group[k]];
    const Eigen::Vector3d expected(2, 1 - (x.z() - 1), 1 + (x.y() - 1) + 0.4);
    EXPECT_LT((Eigen::Vector3d(&last.targets[3 * k]) - expected).norm(), 1e-12) << "vertex " << group[k];
  }
  // Half-way (s = 1/2): 45 degrees and half the drag.
  const Recorder::Step& half = target.steps[1];
  const double c = std::cos(M_PI / 4), s = std::sin(M_PI / 4);
  for (size_t k = 0; k < group.size(); ++k) {
    const Eigen::Vector3d x = mesh.vertices[group[k]];
    const double y = x.y() - 1, z = x.z() - 1;
    const Eigen::Vector3d expected(2, 1 + c * y - s * z, 1 + s * y + c * z + 0.2);
    EXPECT_LT((Eigen::Vector3d(&half.targets[3 * k]) - expected).norm(), 1e-12);
  }
  EXPECT_FALSE(target.steps[4].springs) << "released at the hold";
  EXPECT_FALSE(target.steps[5].springs);
}

TEST(Scenario, OutputFilesAndFailedStepsAreCounted) {
  const fs::path dir = quiver::test::tempDir("ScenarioOutput");
  SimOptions o;
  o.steps = 7;
  o.holdSteps = 0;
  o.every = 3;
  o.output = (dir / "sub" / "run").string();
  Recorder target;
  target.failAt = 2;
  const ScenarioResult result = runScenario(target, box(), o);
  EXPECT_EQ(result.failedSteps, 1);
  EXPECT_TRUE(fs::exists(dir / "sub" / "run_00003.vtu"));
  EXPECT_TRUE(fs::exists(dir / "sub" / "run_00006.vtu"));
  EXPECT_FALSE(fs::exists(dir / "sub" / "run_00007.vtu"));
  std::ifstream pvd(dir / "sub" / "run.pvd"), csv(dir / "sub" / "run.csv");
  const std::string collection((std::istreambuf_iterator<char>(pvd)), {});
  EXPECT_NE(collection.find("timestep=\"1.500000\" part=\"0\" file=\"run_00003.vtu\""), std::string::npos) << collection;
  EXPECT_NE(collection.find("timestep=\"3.000000\" part=\"0\" file=\"run_00006.vtu\""), std::string::npos);
  std::vector<std::string> lines;
  for (std::string line; std::getline(csv, line);) lines.push_back(line);
  ASSERT_EQ(lines.size(), 8u);
  EXPECT_EQ(lines[0], "step,time_s,kinetic_J,elastic_J,step_us,newton,status");
  EXPECT_EQ(lines[3].rfind("3,1.5,1,2,", 0), 0u) << lines[3];
  EXPECT_EQ(lines[3].back(), '1') << "the failed step's status";
}

// A crafted model's energy can fall below zero, which no StVK energy does: named with its step,
// unless it is rounding (1e-6 of the largest energy).
TEST(Scenario, ANegativeElasticEnergyIsNamedWithItsStep) {
  SimOptions o;
  o.steps = 5;
  o.holdSteps = 0;
  Recorder target;
  target.elasticAfter = {{2, -0.25}, {3, -0.5}, {4, 4}};
  ScenarioResult result = runScenario(target, box(), o);
  EXPECT_EQ(result.lowestElastic, -0.5);
  EXPECT_EQ(result.lowestElasticStep, 3);
  EXPECT_EQ(result.largestEnergy, 5);  // 1 J kinetic + 4 J
  EXPECT_NE(negativeEnergyWarning(result).find("fell to -0.5 J (step 3)"), std::string::npos) << negativeEnergyWarning(result);
  Recorder rounding;
  rounding.elasticAfter = {{2, -1e-9}};
  result = runScenario(rounding, box(), o);
  EXPECT_EQ(result.lowestElasticStep, 2);
  EXPECT_EQ(negativeEnergyWarning(result), "");
}

TEST(Scenario, AGroupThatSelectsNothingIsNamed) {
  EXPECT_EQ(quiver::test::errorOf<std::runtime_error>([] { selectGroup(box(), "x>5"); }),
            "--group 'x>5' selects no vertex");
  EXPECT_NE(quiver::test::errorOf<std::runtime_error>([] { selectGroup(box(), "q<1"); }).find("--group: "), std::string::npos);
}

TEST(Scenario, FlightStartsFromTheOptionsAndNeedsFree) {
  SimOptions o;
  o.steps = 1;
  o.flight.velocity = {1, 2, 3};
  Recorder target;
  try {
    runScenario(target, box(), o);
    ADD_FAILURE() << "--velocity without --free was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("need --free"), std::string::npos) << e.what();
  }
  o.step.freeFlight = true;
  runScenario(target, box(), o);
  EXPECT_EQ(target.flight, Eigen::Vector3d(1, 2, 3));
}
