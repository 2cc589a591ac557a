#include "apps/support/scenario_file.h"

#include <gtest/gtest.h>

#include <fstream>
#include <stdexcept>

#include "tests/support/test_support.h"

namespace quiver::app {
namespace {

const std::vector<std::string> kKnown{"twist", "drag", "gravity", "group", "steps"};

TEST(ScenarioFile, OptionsBecomeTokensInOrder) {
  const std::string text = "# a twist\n\ngroup = x>max-1e-6   # the free end\n twist=60\ndrag = 0,0.05,0\ngravity = true\n";
  EXPECT_EQ(parseScenarioFile(text, "t.txt", kKnown),
            (std::vector<std::string>{"--group=x>max-1e-6", "--twist=60", "--drag=0,0.05,0", "--gravity=true"}));
}

TEST(ScenarioFile, MistakesNameTheFileAndLine) {
  const std::pair<const char*, const char*> cases[] = {
      {"twist 60", "t.txt:1: expected 'name = value'"},
      {"\nbogus = 1", "t.txt:2: 'bogus' is not a scenario option (twist, drag, gravity, group, steps)"},
      {"twist =", "t.txt:1: twist has no value"},
      {"scenario = other.txt", "'scenario' is not a scenario option"},
  };
  for (const auto& [text, message] : cases) {
    try {
      parseScenarioFile(text, "t.txt", kKnown);
      ADD_FAILURE() << "accepted: " << text;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
    }
  }
}

TEST(ScenarioFile, ExpandsInPlaceSoLaterOptionsOverrideIt) {
  const std::string path = test::tempDir("ScenarioFile") + "/twist.txt";
  std::ofstream(path) << "twist = 60\nsteps = 10\n";
  EXPECT_EQ(expandScenarioFiles({"render", "m.qvr", "--scenario", path, "--steps", "20"}, kKnown),
            (std::vector<std::string>{"render", "m.qvr", "--twist=60", "--steps=10", "--steps", "20"}));
  EXPECT_EQ(expandScenarioFiles({"--scenario=" + path}, kKnown), (std::vector<std::string>{"--twist=60", "--steps=10"}));
  EXPECT_THROW(expandScenarioFiles({"sim", "--scenario"}, kKnown), std::runtime_error);
  try {
    expandScenarioFiles({"--scenario", "/nonexistent/s.txt"}, kKnown);
    ADD_FAILURE();
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/s.txt"), std::string::npos) << e.what();
  }
}

} // namespace
} // namespace quiver::app
