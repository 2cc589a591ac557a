// Loads::changedSinceLastStep(), which the energy budgets ask at a step's start: a fixed Newton
// step and the minimiser that takes it over both ask, so the answer must not depend on how often.
#include <gtest/gtest.h>

#include <vector>

#include "runtime/src/block_carver.h"
#include "runtime/src/loads.h"

namespace {

struct TestLoads {
  std::vector<double> memory;
  quiver::rt::Loads loads;
  explicit TestLoads(int r) {
    quiver::rt::BlockCarver measure(nullptr);
    loads.carve(measure, r, 1, false);
    memory.resize(measure.size() / sizeof(double) + 8);
    quiver::rt::BlockCarver place(reinterpret_cast<char*>(memory.data()));
    loads.carve(place, r, 1, false);
    loads.clear();
  }
};

} // namespace

TEST(Loads, ChangedSinceLastStepGivesOneAnswerPerStep) {
  TestLoads t(3);
  quiver::rt::Loads& loads = t.loads;
  EXPECT_FALSE(loads.changedSinceLastStep());
  const double push[3] = {1, 0, 0};
  loads.addReducedForce(push);  // a per-step force the last step did not have
  EXPECT_TRUE(loads.changedSinceLastStep());
  EXPECT_TRUE(loads.changedSinceLastStep());
  loads.endStep();
  loads.addReducedForce(push);  // the same again: no change
  EXPECT_FALSE(loads.changedSinceLastStep());
  loads.endStep();
  loads.changed = true;  // what setting a persistent load (gravity, a constraint) records
  loads.addReducedForce(push);
  EXPECT_TRUE(loads.changedSinceLastStep());
  EXPECT_TRUE(loads.changedSinceLastStep());  // asked again within the step: the same answer
  loads.endStep();
  loads.addReducedForce(push);
  EXPECT_FALSE(loads.changedSinceLastStep());  // the next step's loads are the last step's
  loads.endStep();
  loads.changed = true;  // a step that never asks (central differences) still spends the record
  loads.addReducedForce(push);
  loads.endStep();
  loads.addReducedForce(push);
  EXPECT_FALSE(loads.changedSinceLastStep());
}
