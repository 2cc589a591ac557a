#include "tests/support/test_support.h"

#include <filesystem>

namespace fs = std::filesystem;

namespace quiver::test {

std::string sharedMesh(const std::string& name) {
  fs::path p = fs::path(QUIVER_SHARED_MESHES) / name;
  return fs::exists(p) ? p.string() : std::string();
}

std::string asset(const std::string& name) { return (fs::path(QUIVER_TEST_ASSETS) / name).string(); }

std::string tempDir(const std::string& testName) {
  fs::path p = fs::temp_directory_path() / ("quiver-test-" + testName);
  fs::remove_all(p);
  fs::create_directories(p);
  return p.string();
}

} // namespace quiver::test
