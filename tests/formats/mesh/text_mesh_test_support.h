#pragma once
// Helpers shared by the Medit, MFEM and TetGen reader/writer tests.
#include <algorithm>
#include <cctype>
#include <cstring>
#include <memory>
#include <random>
#include <string>
#include <string_view>
#include <utility>

#include <gtest/gtest.h>

#include "common/box_mesh.h"
#include "common/mesh_error.h"
#include "tests/support/test_support.h"

namespace quiver::test {

// The message of the MeshError `parse()` throws, or "" when it returns (other exceptions propagate).
template <class Parse>
std::string meshErrorOf(Parse&& parse) {
  return errorOf<MeshError>(std::forward<Parse>(parse));
}

// `message` is "FILE:LINE: ..." and contains `what`.
inline void expectErrorAt(const std::string& message, const std::string& file, int line, const std::string& what) {
  const std::string prefix = file + ":" + std::to_string(line) + ": ";
  EXPECT_EQ(message.compare(0, prefix.size(), prefix), 0) << "expected a message starting '" << prefix << "', got '"
                                                           << message << "'";
  EXPECT_NE(message.find(what), std::string::npos) << "expected '" << what << "' in '" << message << "'";
}

// 1-based line of the first occurrence of `needle` in `text`.
inline int lineOf(std::string_view text, std::string_view needle) {
  const size_t at = text.find(needle);
  if (at == std::string_view::npos) {
    ADD_FAILURE() << "'" << needle << "' is not in the test text";
    return 0;
  }
  return 1 + static_cast<int>(std::count(text.begin(), text.begin() + at, '\n'));
}

// `text` with its first `from` replaced by `to`.
inline std::string replaced(std::string text, std::string_view from, std::string_view to) {
  const size_t at = text.find(from);
  if (at == std::string::npos) {
    ADD_FAILURE() << "'" << from << "' is not in the test text";
    return text;
  }
  return text.replace(at, from.size(), to);
}

// Calls parse(prefix) on every prefix of `text` shorter than the start of its last token (cutting
// inside the last number may leave a shorter valid number) and expects each to throw a MeshError
// naming `file`. Each prefix sits in a buffer of exactly its size, so over-reads are real ones.
template <class Parse>
void expectEveryCutFails(std::string_view text, const std::string& file, Parse&& parse) {
  size_t lastToken = text.find_last_not_of(" \t\r\n");
  ASSERT_NE(lastToken, std::string_view::npos);
  while (lastToken > 0 && !std::isspace(static_cast<unsigned char>(text[lastToken - 1]))) --lastToken;
  for (size_t k = 0; k <= lastToken; ++k) {
    std::unique_ptr<char[]> buffer(new char[k]);
    std::memcpy(buffer.get(), text.data(), k);
    const std::string message = meshErrorOf([&] { parse(std::string_view(buffer.get(), k)); });
    ASSERT_NE(message.find(file), std::string::npos) << "cut after " << k << " bytes: '" << message << "'";
  }
}

// A 3x2x2-cell box whose vertices are moved by up to 30% of a cell and scaled by 1/3, so that most
// coordinates need all 17 significant digits; regions cycle through 1, 2, 3 and -7.
inline TetMesh jitteredBox(unsigned seed) {
  TetMesh mesh = makeBoxMesh(Eigen::Vector3d(3, 2, 2), {3, 2, 2});
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> jitter(-0.3, 0.3);
  for (Eigen::Vector3d& x : mesh.vertices)
    for (int d = 0; d < 3; ++d) x[d] = (x[d] + jitter(random)) / 3.0;
  mesh.vertices[1] = Eigen::Vector3d(1e-300, -0.0, 12345678.901234567);  // tiny, negative zero, large
  const int regions[] = {1, 2, 3, -7};
  for (int t = 0; t < mesh.tetCount(); ++t) mesh.tetRegion[t] = regions[t % 4];
  return mesh;
}

// Coordinates equal bit for bit (so -0.0 stays -0.0), tets and regions equal.
inline void expectSameMesh(const TetMesh& expected, const TetMesh& actual) {
  ASSERT_EQ(actual.vertexCount(), expected.vertexCount());
  for (int v = 0; v < expected.vertexCount(); ++v)
    EXPECT_EQ(std::memcmp(actual.vertices[v].data(), expected.vertices[v].data(), 3 * sizeof(double)), 0)
        << "vertex " << v << ": " << actual.vertices[v].transpose() << " != " << expected.vertices[v].transpose();
  EXPECT_EQ(actual.tets, expected.tets);
  EXPECT_EQ(actual.tetRegion, expected.tetRegion);
}

} // namespace quiver::test
