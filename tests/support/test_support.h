#pragma once
// Small helpers shared by the tests: locating data, making scratch folders, catching errors.
#include <string>

namespace quiver::test {

// Path of a file in ../shared/meshes, or "" when that folder is absent (callers GTEST_SKIP).
std::string sharedMesh(const std::string& name);

// Path of a file in tests/assets.
std::string asset(const std::string& name);

// A fresh, empty folder for one test's files.
std::string tempDir(const std::string& testName);

// The message of the `Error` that `call()` throws, or "" when it returns (other exceptions propagate).
template <class Error, class Call>
std::string errorOf(Call&& call) {
  try {
    call();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

} // namespace quiver::test

// Skips the current test, saying why, when ../shared/meshes is absent.
#define QUIVER_REQUIRE_SHARED_MESH(var, name)                                                   \
  const std::string var = ::quiver::test::sharedMesh(name);                                     \
  if (var.empty()) GTEST_SKIP() << "shared mesh folder absent (" QUIVER_SHARED_MESHES "): skipping " << (name)
