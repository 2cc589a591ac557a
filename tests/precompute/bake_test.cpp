// The bake's own small contracts that need no mesh.
#include <gtest/gtest.h>

#include <string>

#include "precompute/bake.h"
#include "quiver/quiver.h"

// The archive records the project's version; the runtime a game links must report the same one.
TEST(Bake, RecordsTheVersionTheRuntimeReports) { EXPECT_STREQ(quiver::bakeVersion(), qv_version_string()); }

TEST(Bake, SettingsThatNeedNoMeshAreCheckedBeforeAnyWork) {
  quiver::BakeSettings s;
  s.output.name = "out";
  EXPECT_NO_THROW(quiver::checkBakeSettings(s));
  s.basis.settings.rank = 40;
  s.modes = 3;
  EXPECT_NO_THROW(quiver::checkBakeSettings(s)) << "fewer vectors than asked is a warning at the basis stage";
  s.basis.settings.exactRank = true;
  EXPECT_THROW(quiver::checkBakeSettings(s), std::invalid_argument);
  s.basis.settings.exactRank = false;
  s.mesh.material.poissonRatio = 0.5;
  EXPECT_THROW(quiver::checkBakeSettings(s), std::invalid_argument);
}
