#include "apps/view/drag_script.h"

#include <gtest/gtest.h>

#include <stdexcept>

#include "tests/support/test_support.h"

namespace quiver::app {
namespace {

TEST(DragScript, PressGlideHoldRelease) {
  const DragScript script = DragScript::parse("# a drag\n\n10 press 0.8 0.4\n40 move 0.8 0.7  # down\n90 release\n", "s");
  EXPECT_FALSE(script.at(9).down);
  ScriptedCursor c = script.at(10);
  EXPECT_TRUE(c.down);
  EXPECT_DOUBLE_EQ(c.x, 0.8);
  EXPECT_DOUBLE_EQ(c.y, 0.4);
  c = script.at(25);  // half way through the glide
  EXPECT_TRUE(c.down);
  EXPECT_NEAR(c.y, 0.55, 1e-12);
  c = script.at(60);
  EXPECT_TRUE(c.down);
  EXPECT_DOUBLE_EQ(c.y, 0.7);
  EXPECT_FALSE(script.at(90).down);
  EXPECT_FALSE(script.at(1000).down);
}

TEST(DragScript, AnEmptyScriptNeverPresses) { EXPECT_FALSE(DragScript::parse("# nothing\n", "s").at(5).down); }

TEST(DragScript, MistakesNameTheFileAndLine) {
  const std::pair<const char*, const char*> cases[] = {
      {"x press 0 0", "s.txt:1: 'x' is not a frame number"},
      {"5 press 0 0\n3 release", "s.txt:2: frame 3 comes before"},
      {"5 press 0.5", "s.txt:1: press needs X Y"},
      {"5 press 1.5 0", "s.txt:1: X and Y are fractions"},
      {"5 release", "s.txt:1: release without a press"},
      {"1 press 0 0\n2 press 0 0", "s.txt:2: press while the button is already pressed"},
      {"1 jump", "s.txt:1: unknown action 'jump'"},
      {"1 press 0 0 0", "s.txt:1: unexpected '0'"},
      {"-1 press 0 0", "s.txt:1: '-1' is not a frame number"},
  };
  for (const auto& [text, message] : cases) {
    const std::string error = test::errorOf<std::runtime_error>([t = text] { DragScript::parse(t, "s.txt"); });
    EXPECT_NE(error.find(message), std::string::npos) << "'" << text << "' gave '" << error << "'";
  };
}

TEST(DragScript, AMissingFileIsNamed) {
  try {
    DragScript::load("/nonexistent/drag.txt");
    ADD_FAILURE();
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/drag.txt"), std::string::npos) << e.what();
  }
}

} // namespace
} // namespace quiver::app
