// The fixed-vertex options as the tools parse them: index lists and .bou files become the lists
// common/fixed_vertices.h maps onto the mesh.
#include <gtest/gtest.h>

#include <fstream>

#include "apps/support/mesh_options.h"
#include "common/mesh_error.h"
#include "tests/support/test_support.h"

using namespace quiver;
using namespace quiver::app;

TEST(FixedVertexOptions, IndexListsAndBouFilesResolveToNamedLists) {
  EXPECT_EQ(parseIndexList("1,4-6", "--fix-indices"), (std::vector<int64_t>{1, 4, 5, 6}));
  EXPECT_EQ(test::errorOf<MeshError>([] { parseIndexList("1,x", "--fix-indices"); }),
            "--fix-indices: 'x' is not a vertex index or range like 10-12 (0-based)");
  EXPECT_THROW(parseIndexList("5-2", "--fix-indices"), MeshError);
  EXPECT_THROW(parseIndexList("", "--fix-indices"), MeshError);

  const std::string bou = test::tempDir("fixed_options") + "/f.bou";
  std::ofstream(bou) << "2,3\n";
  CLI::App app;
  FixedVertexOptions o;
  o.addTo(app);
  EXPECT_FALSE(o.given());
  app.parse("--bou " + bou + " --fix-indices 7,9 --fix x<0", false);
  ASSERT_TRUE(o.given());
  const FixedVertexRequest r = o.resolved();
  EXPECT_EQ(r.selectors, std::vector<std::string>{"x<0"});
  ASSERT_EQ(r.lists.size(), 2u);
  EXPECT_EQ(r.lists[0].source, "--fix-indices");
  EXPECT_EQ(r.lists[0].indices, (std::vector<int64_t>{7, 9}));
  EXPECT_EQ(r.lists[1].source, bou);
  EXPECT_EQ(r.lists[1].indices, (std::vector<int64_t>{1, 2}));
  EXPECT_EQ(r.lists[1].firstNumber, 1);
}
