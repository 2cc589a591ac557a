#include "apps/support/scenario_file.h"

#include <gtest/gtest.h>

#include <fstream>
#include <stdexcept>

#include "tests/support/test_support.h"

namespace quiver::app {
namespace {

// A stand-in for SimOptions::checkScenarioOption (the quiver tool's, tested through the tool).
std::string kKnown(const std::string& name, const std::string& value) {
  if (name != "twist" && name != "drag" && name != "gravity" && name != "group" && name != "steps")
    return "'" + name + "' is not a scenario option";
  return value == "bad" ? name + " cannot be 'bad'" : "";
}

TEST(ScenarioFile, OptionsBecomeTokensInOrder) {
  const std::string text = "# a twist\n\ngroup = x>max-1e-6   # the free end\n twist=60\ndrag = 0,0.05,0\ngravity = true\n";
  EXPECT_EQ(parseScenarioFile(text, "t.txt", kKnown),
            (std::vector<std::string>{"--group=x>max-1e-6", "--twist=60", "--drag=0,0.05,0", "--gravity=true"}));
}

TEST(ScenarioFile, MistakesNameTheFileAndLine) {
  const std::pair<const char*, const char*> cases[] = {
      {"twist 60", "t.txt:1: expected 'name = value'"},
      {"\nbogus = 1", "t.txt:2: 'bogus' is not a scenario option"},
      {"twist =", "t.txt:1: twist has no value"},
      {"steps = 3\ntwist = bad", "t.txt:2: twist cannot be 'bad'"},
      {"# only a comment\n", "t.txt: sets no scenario option"},
  };
  for (const auto& [text, message] : cases) {
    const std::string error = test::errorOf<std::runtime_error>([&, t = text] { parseScenarioFile(t, "t.txt", kKnown); });
    EXPECT_NE(error.find(message), std::string::npos) << "'" << text << "' gave '" << error << "'";
  };
}

TEST(ScenarioFile, ExpandsInPlaceSoLaterOptionsOverrideIt) {
  const std::string path = test::tempDir("ScenarioFile") + "/twist.txt";
  std::ofstream(path) << "twist = 60\nsteps = 10\n";
  EXPECT_EQ(expandScenarioFiles({"render", "m.qvr", "--scenario", path, "--steps", "20"}, kKnown),
            (std::vector<std::string>{"render", "m.qvr", "--twist=60", "--steps", "20"}));
  EXPECT_EQ(expandScenarioFiles({"--twist", "5", "--scenario=" + path, "--steps=30"}, kKnown),
            (std::vector<std::string>{"--twist", "5", "--twist=60", "--steps=30"}))
      << "only later options override the file's (an earlier --twist stays, and CLI11 refuses the pair)";
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
