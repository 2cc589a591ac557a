#include <gtest/gtest.h>

#include <stdexcept>

#include "common/box_mesh.h"
#include "common/vertex_selector.h"

using namespace quiver;

namespace {
// 3 x 2 x 2 vertices on [0,2]x[0,1]x[0,1]: x = 0,1,2.
const TetMesh kBox = makeBoxMesh({2, 1, 1}, {2, 1, 1});

std::vector<int> brute(bool (*keep)(const Eigen::Vector3d&)) {
  std::vector<int> out;
  for (int v = 0; v < kBox.vertexCount(); ++v)
    if (keep(kBox.vertices[v])) out.push_back(v);
  return out;
}
} // namespace

TEST(VertexSelector, ComparisonsAndConjunctions) {
  EXPECT_EQ(VertexSelector("x<0.5").select(kBox), brute([](const Eigen::Vector3d& x) { return x.x() < 0.5; }));
  EXPECT_EQ(VertexSelector("x <= 1").select(kBox), brute([](const Eigen::Vector3d& x) { return x.x() <= 1; }));
  EXPECT_EQ(VertexSelector("x>1 & z>=0.5").select(kBox),
            brute([](const Eigen::Vector3d& x) { return x.x() > 1 && x.z() >= 0.5; }));
  EXPECT_EQ(VertexSelector("y>-1e3").select(kBox).size(), 12u);
}

TEST(VertexSelector, BoundingBoxRelativeValues) {
  EXPECT_EQ(VertexSelector("x>=max").select(kBox), brute([](const Eigen::Vector3d& x) { return x.x() == 2; }));
  EXPECT_EQ(VertexSelector("x<min+0.5").select(kBox), brute([](const Eigen::Vector3d& x) { return x.x() == 0; }));
  EXPECT_EQ(VertexSelector("x>max-1.5").select(kBox), brute([](const Eigen::Vector3d& x) { return x.x() >= 1; }));
}

TEST(VertexSelector, Box) {
  EXPECT_EQ(VertexSelector("box:0.5,-1,-1,1.5,1,1").select(kBox),
            brute([](const Eigen::Vector3d& x) { return x.x() == 1; }));
}

TEST(VertexSelector, MalformedExpressionsSayWhere) {
  for (const char* bad : {"", "w<1", "x=1", "x<", "x<abc", "x<1 &", "x<1 y>2", "box:1,2,3", "box:1,0,0,0,1,1"}) {
    try {
      VertexSelector s(bad);
      FAIL() << "accepted '" << bad << "'";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(std::string("'") + bad + "'"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("at character"), std::string::npos) << e.what();
    }
  }
}
