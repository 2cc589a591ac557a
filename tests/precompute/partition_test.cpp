#include <gtest/gtest.h>

#include <algorithm>
#include <map>

#include "common/box_mesh.h"
#include "precompute/stages/partition.h"

using namespace quiver;

namespace {
// Faces shared by two tets of different parts, counted directly from the connectivity.
int countCutFaces(const TetMesh& mesh, const std::vector<int>& tetPart) {
  std::map<std::array<int, 3>, std::vector<int>> faces;
  for (int t = 0; t < mesh.tetCount(); ++t)
    for (int skip = 0; skip < 4; ++skip) {
      std::array<int, 3> f;
      int k = 0;
      for (int i = 0; i < 4; ++i)
        if (i != skip) f[k++] = mesh.tets[t][i];
      std::sort(f.begin(), f.end());
      faces[f].push_back(t);
    }
  int cut = 0;
  for (const auto& [f, tets] : faces)
    if (tets.size() == 2 && tetPart[tets[0]] != tetPart[tets[1]]) ++cut;
  return cut;
}
} // namespace

TEST(Partition, OnePartOwnsEverything) {
  TetMesh mesh = makeBoxMesh({1, 1, 1}, {2, 2, 2});
  Partition p = partitionMesh(mesh, {1});
  EXPECT_TRUE(std::all_of(p.tetPart.begin(), p.tetPart.end(), [](int x) { return x == 0; }));
  EXPECT_TRUE(std::all_of(p.vertexPart.begin(), p.vertexPart.end(), [](int x) { return x == 0; }));
  EXPECT_EQ(p.cutFaces, 0);
}

TEST(Partition, BalancedPartsAndReportedCutMatchesConnectivity) {
  TetMesh mesh = makeBoxMesh({4, 1, 1}, {16, 4, 4});
  for (int parts : {2, 3, 4}) {
    Partition p = partitionMesh(mesh, {parts});
    std::vector<int> count(parts, 0);
    for (int x : p.tetPart) {
      ASSERT_GE(x, 0);
      ASSERT_LT(x, parts);
      ++count[x];
    }
    for (int c : count) EXPECT_NEAR(c, mesh.tetCount() / double(parts), 0.1 * mesh.tetCount() / parts);
    EXPECT_EQ(p.cutFaces, countCutFaces(mesh, p.tetPart));
    // A beam cut into slabs needs about (parts - 1) cross-sections of 4*4*2 faces: far below random.
    EXPECT_LT(p.cutFaces, 4 * (parts - 1) * 4 * 4 * 2);
    // Every vertex belongs to a part one of its tets belongs to.
    for (int t = 0; t < mesh.tetCount(); ++t)
      for (int v : mesh.tets[t]) EXPECT_LE(p.vertexPart[v], p.tetPart[t]);
    // Same seed, same answer: every rank computes the same partition.
    EXPECT_EQ(partitionMesh(mesh, {parts}).tetPart, p.tetPart);
  }
}

TEST(Partition, MorePartsThanTetsIsAnError) {
  TetMesh mesh = makeBoxMesh({1, 1, 1}, {1, 1, 1});
  EXPECT_THROW(partitionMesh(mesh, {7}), std::runtime_error);
}
