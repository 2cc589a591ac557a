// writeFileAtomically: readers see the old file or the new one, never a half-written one, and a
// failure leaves what was there untouched with no temporary behind.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <sys/stat.h>

#include "formats/atomic_file.h"
#include "tests/support/test_support.h"

namespace fs = std::filesystem;

namespace {

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

struct AtomicFile : ::testing::Test {
  fs::path dir = quiver::test::tempDir(::testing::UnitTest::GetInstance()->current_test_info()->name());
  size_t entries() const { return static_cast<size_t>(std::distance(fs::directory_iterator(dir), fs::directory_iterator())); }
};

} // namespace

TEST_F(AtomicFile, WritesAndReplacesWithNothingLeftBehind) {
  const fs::path p = dir / "out.bin";
  const std::string first("first\0with a NUL", 16), second(1 << 20, 'x');
  quiver::writeFileAtomically(p.string(), first);
  EXPECT_EQ(slurp(p), first);
  quiver::writeFileAtomically(p.string(), second);
  EXPECT_EQ(slurp(p), second);
  quiver::writeFileAtomically(p.string(), "");
  EXPECT_EQ(fs::file_size(p), 0u);
  EXPECT_EQ(entries(), 1u) << "no temporary file may stay beside it";
}

TEST_F(AtomicFile, PermissionsAreAnOrdinaryCreatesNotMkstemps) {
  const fs::path p = dir / "mode.txt";
  const mode_t mask = ::umask(022);
  quiver::writeFileAtomically(p.string(), "x");
  ::umask(mask);
  struct stat st {};
  ASSERT_EQ(::stat(p.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0644u);
}

TEST_F(AtomicFile, FailuresNameThePathAndLeaveTheOldFile) {
  // A missing folder: nothing can be created.
  const std::string missing = (dir / "no such folder" / "out.txt").string();
  try {
    quiver::writeFileAtomically(missing, "x");
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(missing), std::string::npos) << e.what();
  }
  // The target is a folder: the rename fails after the bytes were written; the temporary goes.
  const fs::path folder = dir / "taken";
  fs::create_directories(folder / "inside");
  EXPECT_THROW(quiver::writeFileAtomically(folder.string(), "x"), std::runtime_error);
  EXPECT_TRUE(fs::is_directory(folder / "inside"));
  EXPECT_EQ(entries(), 1u) << "the temporary must be removed after a failed rename";
}
