// The bake archive with real parallel HDF5, on however many ranks mpirun starts (1 and 2 in ctest).
#include <gtest/gtest.h>
#include <hdf5.h>
#include <tinyxml2.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <numeric>
#include <sstream>

#include "precompute/archive/archive.h"
#include "precompute/archive/xdmf.h"
#include "tests/support/test_support.h"

using namespace quiver;

namespace {

int commRank() {
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  return rank;
}
int commSize() {
  int size = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  return size;
}

// Each test gets a fresh folder, named by rank 0 and shared with the other ranks.
class ArchiveTest : public ::testing::Test {
protected:
  void SetUp() override {
    std::string dir;
    if (rank == 0)
      dir = test::tempDir("archive-" + std::to_string(getpid()) + "-" +
                          ::testing::UnitTest::GetInstance()->current_test_info()->name());
    int length = static_cast<int>(dir.size());
    MPI_Bcast(&length, 1, MPI_INT, 0, MPI_COMM_WORLD);
    dir.resize(static_cast<size_t>(length));
    MPI_Bcast(dir.data(), length, MPI_CHAR, 0, MPI_COMM_WORLD);
    dir_ = dir;
  }
  void TearDown() override {
    MPI_Barrier(MPI_COMM_WORLD);
    if (rank == 0) std::filesystem::remove_all(dir_);
  }
  std::string file(const std::string& name) const { return dir_ + "/" + name; }

  const int rank = commRank(), size = commSize();

private:
  std::string dir_;
};

int64_t product(const std::vector<int64_t>& shape) {
  return std::accumulate(shape.begin(), shape.end(), int64_t(1), std::multiplies<>());
}

// The elements of `whole` (row-major, `shape`) whose index along `axis` is in [start, start + count).
std::vector<double> slabOf(const std::vector<double>& whole, const std::vector<int64_t>& shape, int axis,
                           int64_t start, int64_t count) {
  const int64_t outer = product({shape.begin(), shape.begin() + axis});
  const int64_t inner = product({shape.begin() + axis + 1, shape.end()});
  std::vector<double> out;
  for (int64_t o = 0; o < outer; ++o)
    for (int64_t a = start; a < start + count; ++a)
      for (int64_t i = 0; i < inner; ++i) out.push_back(whole[(o * shape[axis] + a) * inner + i]);
  return out;
}

// Rank 0 takes `first` entries (all of them when alone); the other ranks split the rest evenly.
std::pair<int64_t, int64_t> split(int64_t extent, int rank, int size, int64_t first) {
  if (size == 1) return {0, extent};
  if (rank == 0) return {0, first};
  const int64_t rest = extent - first, others = size - 1, r = rank - 1;
  const int64_t start = first + rest * r / others;
  return {start, first + rest * (r + 1) / others - start};
}

// Runs `f`, expecting a std::runtime_error whose message contains every one of `parts`.
void expectErrorNaming(const std::function<void()>& f, const std::vector<std::string>& parts) {
  try {
    f();
    ADD_FAILURE() << "no error; expected one naming " << parts.front();
  } catch (const std::runtime_error& e) {
    for (const std::string& p : parts) EXPECT_NE(std::string(e.what()).find(p), std::string::npos) << e.what();
  }
}

std::vector<int64_t> datasetDims(hid_t file, const std::string& path) {
  hid_t dataset = H5Dopen2(file, path.c_str(), H5P_DEFAULT);
  if (dataset < 0) return {};
  hid_t space = H5Dget_space(dataset);
  std::vector<hsize_t> dims(static_cast<size_t>(H5Sget_simple_extent_ndims(space)));
  H5Sget_simple_extent_dims(space, dims.data(), nullptr);
  H5Sclose(space);
  H5Dclose(dataset);
  return {dims.begin(), dims.end()};
}

std::vector<int64_t> parseNumbers(const char* text) {
  std::istringstream in(text ? text : "");
  std::vector<int64_t> values;
  for (int64_t v; in >> v;) values.push_back(v);
  return values;
}

} // namespace

TEST_F(ArchiveTest, ReplicatedDatasetsOfEveryTypeAndRankRoundTrip) {
  const std::vector<std::vector<int64_t>> shapes = {{}, {5}, {4, 3}, {2, 3, 4}, {0, 3}};
  {
    Archive archive(MPI_COMM_WORLD, file("a.h5"), Archive::Mode::Create);
    for (size_t s = 0; s < shapes.size(); ++s) {
      const int64_t count = product(shapes[s]);
      // Only rank 0's data is written: the other ranks pass garbage.
      std::vector<double> d(static_cast<size_t>(count), -999);
      std::vector<int64_t> l(static_cast<size_t>(count), -999);
      std::vector<int32_t> i(static_cast<size_t>(count), -999);
      for (int64_t k = 0; k < count && rank == 0; ++k) {
        d[k] = 0.25 * static_cast<double>(k) - 1e-300;
        l[k] = (int64_t(1) << 40) + k;
        i[k] = -static_cast<int32_t>(k);
      }
      archive.writeReplicated("/double/" + std::to_string(s), shapes[s], d.data());
      archive.writeReplicated("/int64/" + std::to_string(s), shapes[s], l.data());
      archive.writeReplicated("/int32/" + std::to_string(s), shapes[s], i.data());
    }
  }
  Archive archive(MPI_COMM_WORLD, file("a.h5"), Archive::Mode::ReadOnly);
  for (size_t s = 0; s < shapes.size(); ++s) {
    std::vector<int64_t> shapeD, shapeL, shapeI;
    const std::vector<double> d = archive.readReplicatedDouble("/double/" + std::to_string(s), shapeD);
    const std::vector<int64_t> l = archive.readReplicatedInt("/int64/" + std::to_string(s), shapeL);
    const std::vector<int64_t> i = archive.readReplicatedInt("/int32/" + std::to_string(s), shapeI);
    EXPECT_EQ(shapeD, shapes[s]);
    EXPECT_EQ(shapeL, shapes[s]);
    EXPECT_EQ(shapeI, shapes[s]);
    ASSERT_EQ(static_cast<int64_t>(d.size()), product(shapes[s]));
    ASSERT_EQ(l.size(), d.size());
    ASSERT_EQ(i.size(), d.size());
    for (size_t k = 0; k < d.size(); ++k) {
      EXPECT_EQ(d[k], 0.25 * static_cast<double>(k) - 1e-300);
      EXPECT_EQ(l[k], (int64_t(1) << 40) + static_cast<int64_t>(k));
      EXPECT_EQ(i[k], -static_cast<int64_t>(k));
    }
  }
}

TEST_F(ArchiveTest, SlabsAlongEitherAxisWithUnevenAndEmptyCountsReadBackWholeAndAsSlabs) {
  struct Case {
    std::string path;
    std::vector<int64_t> shape;
    int axis;
    int64_t firstCount;  // rank 0's share; the other ranks split the rest
  };
  const std::vector<Case> cases = {{"/modes/vectors", {3, 7, 3}, 1, 5},
                                   {"/modes/empty_first", {3, 7, 3}, 1, 0},
                                   {"/rows/uneven", {5, 4}, 0, 3},
                                   {"/rows/empty_first", {5, 4}, 0, 0}};
  auto wholeOf = [](const std::vector<int64_t>& shape) {
    std::vector<double> v(static_cast<size_t>(product(shape)));
    for (size_t k = 0; k < v.size(); ++k) v[k] = 0.5 * static_cast<double>(k) + 1;
    return v;
  };
  {
    Archive archive(MPI_COMM_WORLD, file("s.h5"), Archive::Mode::Create);
    for (const Case& c : cases) {
      const auto [start, count] = split(c.shape[c.axis], rank, size, c.firstCount);
      const std::vector<double> mine = slabOf(wholeOf(c.shape), c.shape, c.axis, start, count);
      archive.writeSlab(c.path, c.shape, c.axis, start, count, mine.data());
    }
  }
  Archive archive(MPI_COMM_WORLD, file("s.h5"), Archive::Mode::ReadOnly);
  for (const Case& c : cases) {
    SCOPED_TRACE(c.path);
    const std::vector<double> whole = wholeOf(c.shape);
    std::vector<int64_t> shape;
    EXPECT_EQ(archive.readReplicatedDouble(c.path, shape), whole);
    EXPECT_EQ(shape, c.shape);
    // Each rank reads another rank's slab, then all read the same overlapping middle slab.
    const auto [start, count] = split(c.shape[c.axis], size - 1 - rank, size, c.firstCount);
    EXPECT_EQ(archive.readSlab(c.path, c.axis, start, count, shape), slabOf(whole, c.shape, c.axis, start, count));
    EXPECT_EQ(shape, c.shape);
    EXPECT_EQ(archive.readSlab(c.path, c.axis, 1, 2, shape), slabOf(whole, c.shape, c.axis, 1, 2));
  }
}

TEST_F(ArchiveTest, AttributesOfEachTypeOnFileGroupsAndDatasets) {
  const std::string utf8 = "quiver bake archive \xe2\x80\x94 \xc3\xbc", longText(100000, 'x');
  const double values[2] = {1.5, 2.5};
  {
    Archive archive(MPI_COMM_WORLD, file("t.h5"), Archive::Mode::Create);
    archive.writeReplicated("/modes/eigenvalues", {2}, values);
    for (const std::string object : {"/", "/modes", "/modes/eigenvalues"}) {
      archive.setAttribute(object, "text", utf8);
      archive.setAttribute(object, "long_text", longText);
      archive.setAttribute(object, "empty_text", std::string());
      archive.setAttribute(object, "real", -1.0 / 3.0);
      archive.setAttribute(object, "count", int64_t(-(int64_t(1) << 53) - 1));
      archive.setAttribute(object, "replaced", std::string("first a string"));
      archive.setAttribute(object, "replaced", int64_t(7));
    }
  }
  Archive archive(MPI_COMM_WORLD, file("t.h5"), Archive::Mode::ReadOnly);
  for (const std::string object : {"/", "/modes", "/modes/eigenvalues"}) {
    SCOPED_TRACE(object);
    EXPECT_EQ(archive.stringAttribute(object, "text"), utf8);
    EXPECT_EQ(archive.stringAttribute(object, "long_text"), longText);
    EXPECT_EQ(archive.stringAttribute(object, "empty_text"), "");
    EXPECT_EQ(archive.doubleAttribute(object, "real"), -1.0 / 3.0);
    EXPECT_EQ(archive.intAttribute(object, "count"), -(int64_t(1) << 53) - 1);
    EXPECT_EQ(archive.intAttribute(object, "replaced"), 7);
    EXPECT_TRUE(archive.hasAttribute(object, "real"));
    EXPECT_FALSE(archive.hasAttribute(object, "absent"));
    EXPECT_THROW(archive.doubleAttribute(object, "text"), std::runtime_error);
    EXPECT_THROW(archive.stringAttribute(object, "count"), std::runtime_error);
  }
  EXPECT_FALSE(archive.hasAttribute("/no/such/group", "real"));
}

TEST_F(ArchiveTest, ExistsRemoveAndRewritingWithAnotherShape) {
  Archive archive(MPI_COMM_WORLD, file("e.h5"), Archive::Mode::Create);
  EXPECT_TRUE(archive.exists("/"));
  EXPECT_FALSE(archive.exists("/a"));
  archive.createGroup("/a/b/c");
  archive.createGroup("/a/b/c");  // already there: nothing to do
  EXPECT_TRUE(archive.exists("/a"));
  EXPECT_TRUE(archive.exists("/a/b/c"));
  EXPECT_FALSE(archive.exists("/a/x"));
  EXPECT_FALSE(archive.exists("/z/y/x"));

  const std::vector<double> ten(10, 3.0);
  archive.writeReplicated("/a/b/data", {10}, ten.data());
  const int32_t six[6] = {1, 2, 3, 4, 5, 6};
  archive.writeReplicated("/a/b/data", {2, 3}, six);
  std::vector<int64_t> shape;
  EXPECT_EQ(archive.readReplicatedInt("/a/b/data", shape), (std::vector<int64_t>{1, 2, 3, 4, 5, 6}));
  EXPECT_EQ(shape, (std::vector<int64_t>{2, 3}));
  const auto [start, count] = split(4, rank, size, 1);
  const std::vector<double> slab(static_cast<size_t>(count), 9.0);
  archive.writeSlab("/a/b/data", {4}, 0, start, count, slab.data());
  EXPECT_EQ(archive.readReplicatedDouble("/a/b/data", shape), std::vector<double>(4, 9.0));

  EXPECT_THROW(archive.createGroup("/a/b/data"), std::runtime_error);        // a dataset is there
  EXPECT_THROW(archive.writeReplicated("/a/b", {1}, six), std::runtime_error);  // a group is there

  archive.removeObject("/a/b");
  EXPECT_FALSE(archive.exists("/a/b/data"));
  EXPECT_FALSE(archive.exists("/a/b"));
  EXPECT_TRUE(archive.exists("/a"));
  expectErrorNaming([&] { archive.removeObject("/a/b"); }, {file("e.h5") + ": /a/b: no such object"});
  archive.flush();
}

TEST_F(ArchiveTest, LayoutSeenThroughTheHdf5CApi) {
  const int64_t n = 6;
  {
    Archive archive(MPI_COMM_WORLD, file("c.h5"), Archive::Mode::Create);
    const auto [start, count] = split(n, rank, size, 4);
    std::vector<double> mine;
    for (int64_t k = 0; k < 2; ++k)
      for (int64_t v = start; v < start + count; ++v)
        for (int c = 0; c < 3; ++c) mine.push_back(100.0 * k + 10.0 * v + c);
    archive.writeSlab("/modes/vectors", {2, n, 3}, 1, start, count, mine.data());
    const int32_t tets[8] = {0, 1, 2, 3, 2, 3, 4, 5};
    archive.writeReplicated("/mesh/tets", {2, 4}, tets);
    archive.setAttribute("/", "format", std::string("quiver bake archive"));
    archive.setAttribute("/", "schema_version", int64_t(1));
  }
  if (rank == 0) {
    hid_t f = H5Fopen(file("c.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
    ASSERT_GE(f, 0);
    hid_t d = H5Dopen2(f, "/modes/vectors", H5P_DEFAULT);
    hid_t type = H5Dget_type(d);
    EXPECT_GT(H5Tequal(type, H5T_IEEE_F64LE), 0);
    H5Tclose(type);
    EXPECT_EQ(datasetDims(f, "/modes/vectors"), (std::vector<int64_t>{2, n, 3}));
    std::vector<double> all(2 * n * 3);
    EXPECT_GE(H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, all.data()), 0);
    for (int64_t k = 0; k < 2; ++k)
      for (int64_t v = 0; v < n; ++v)
        for (int c = 0; c < 3; ++c) EXPECT_EQ(all[(k * n + v) * 3 + c], 100.0 * k + 10.0 * v + c);
    H5Dclose(d);

    d = H5Dopen2(f, "/mesh/tets", H5P_DEFAULT);
    type = H5Dget_type(d);
    EXPECT_GT(H5Tequal(type, H5T_STD_I32LE), 0);
    H5Tclose(type);
    int32_t tets[8] = {};
    EXPECT_GE(H5Dread(d, H5T_NATIVE_INT32, H5S_ALL, H5S_ALL, H5P_DEFAULT, tets), 0);
    EXPECT_EQ(tets[5], 3);
    H5Dclose(d);

    hid_t a = H5Aopen(f, "format", H5P_DEFAULT);
    type = H5Aget_type(a);
    EXPECT_GT(H5Tis_variable_str(type), 0);
    EXPECT_EQ(H5Tget_cset(type), H5T_CSET_UTF8);
    char* text = nullptr;
    EXPECT_GE(H5Aread(a, type, &text), 0);
    EXPECT_STREQ(text, "quiver bake archive");
    free(text);
    H5Tclose(type);
    H5Aclose(a);
    a = H5Aopen(f, "schema_version", H5P_DEFAULT);
    type = H5Aget_type(a);
    EXPECT_GT(H5Tequal(type, H5T_STD_I64LE), 0);
    H5Tclose(type);
    H5Aclose(a);
    H5Fclose(f);
  }
}

TEST_F(ArchiveTest, ErrorsNameFileAndObjectOnEveryRank) {
  const std::string missing = file("missing.h5"), text = file("text.h5"), good = file("g.h5");
  if (rank == 0) std::ofstream(text) << "not an HDF5 file, just text long enough to hold no signature\n";
  MPI_Barrier(MPI_COMM_WORLD);
  expectErrorNaming([&] { Archive a(MPI_COMM_WORLD, missing, Archive::Mode::ReadOnly); }, {missing + ": /: "});
  expectErrorNaming([&] { Archive a(MPI_COMM_WORLD, missing, Archive::Mode::ReadWrite); }, {missing + ": /: "});
  expectErrorNaming([&] { Archive a(MPI_COMM_WORLD, text, Archive::Mode::ReadOnly); }, {text + ": /: "});
  expectErrorNaming([&] { Archive a(MPI_COMM_WORLD, file("no/such/dir.h5"), Archive::Mode::Create); },
                    {file("no/such/dir.h5")});

  Archive archive(MPI_COMM_WORLD, good, Archive::Mode::Create);
  const int64_t one = 1;
  archive.writeReplicated("/ints", {1}, &one);
  const std::vector<double> values(12, 1.0);
  archive.writeReplicated("/reals", {2}, values.data());
  std::vector<int64_t> shape;
  expectErrorNaming([&] { archive.readReplicatedDouble("/modes/vectors", shape); },
                    {good + ": /modes/vectors: no such dataset"});
  expectErrorNaming([&] { archive.readReplicatedInt("/reals/nothing", shape); }, {good + ": /reals/nothing: "});
  expectErrorNaming([&] { archive.readSlab("/modes/vectors", 1, 0, 0, shape); },
                    {good + ": /modes/vectors: no such dataset"});
  expectErrorNaming([&] { archive.readReplicatedDouble("/ints", shape); }, {good + ": /ints: ", "floating-point"});
  expectErrorNaming([&] { archive.intAttribute("/", "schema_version"); },
                    {good + ": / (attribute schema_version): no such attribute"});
  expectErrorNaming([&] { archive.stringAttribute("/absent", "format"); },
                    {good + ": /absent (attribute format): no such object"});

  // A bad slab on one rank, and slabs that leave a gap, fail on every rank alike.
  const int64_t badStart = rank == size - 1 ? 5 : 0;
  expectErrorNaming([&] { archive.writeSlab("/slab", {6}, 0, badStart, 2, values.data()); },
                    {good + ": /slab: ", "rank " + std::to_string(size - 1)});
  expectErrorNaming([&] { archive.writeSlab("/slab", {6}, 0, 0, 2, values.data()); }, {good + ": /slab: ", "tile"});
  expectErrorNaming([&] { archive.writeSlab("/slab", {6}, 3, 0, 6, values.data()); }, {good + ": /slab: ", "axis 3"});
  expectErrorNaming([&] { archive.readSlab("/reals", 0, 1, 2, shape); }, {good + ": /reals: ", "[1, 3) is outside"});

  // The archive still works after all of that.
  const auto [start, count] = split(6, rank, size, 2);
  archive.writeSlab("/slab", {6}, 0, start, count, values.data());
  EXPECT_EQ(archive.readReplicatedDouble("/slab", shape), std::vector<double>(6, 1.0));
}

TEST_F(ArchiveTest, XdmfIsWellFormedAndEveryHeavyItemNamesAnExistingDataset) {
  const int64_t n = 5, m = 2;
  {
    Archive archive(MPI_COMM_WORLD, file("bake.h5"), Archive::Mode::Create);
    const std::vector<double> xyz(3 * n, 0.5);
    const int32_t tets[8] = {0, 1, 2, 3, 1, 2, 3, 4};
    archive.writeReplicated("/mesh/vertices", {n, 3}, xyz.data());
    archive.writeReplicated("/mesh/tets", {m, 4}, tets);
    const auto [start, count] = split(n, rank, size, 2);
    const std::vector<double> slab(static_cast<size_t>(3 * 3 * count), 1.0);
    archive.writeSlab("/modes/vectors", {2, n, 3}, 1, start, count, slab.data());
    archive.writeSlab("/derivatives/vectors", {3, n, 3}, 1, start, count, slab.data());
  }
  if (rank != 0) return;
  writeModesXdmf(file("bake.xmf"), "bake.h5", n, m,
                 {{"/modes/vectors", 2}, {"/derivatives/vectors", 3}, {"/basis/vectors", 0}});
  writeModesXdmf(file("mesh.xmf"), "bake.h5", n, m, {});

  hid_t h5 = H5Fopen(file("bake.h5").c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(h5, 0);
  int heavyItems = 0;
  // Checks every HDF DataItem under `e` against the file: "bake.h5:/path" must be a dataset of the
  // item's Dimensions; "bake.h5:/path|start:stride:count:dataspace" a dataset of dimensions
  // `dataspace` holding the selection, with the item's Dimensions equal to `count`.
  std::function<void(const tinyxml2::XMLElement*)> check = [&](const tinyxml2::XMLElement* e) {
    for (const tinyxml2::XMLElement* c = e->FirstChildElement(); c; c = c->NextSiblingElement()) check(c);
    if (std::string(e->Name()) != "DataItem") return;
    ASSERT_STREQ(e->Attribute("Format"), "HDF");
    const std::vector<int64_t> dims = parseNumbers(e->Attribute("Dimensions"));
    std::string ref = e->GetText(), selection;
    if (ref.find('|') != std::string::npos) {
      selection = ref.substr(ref.find('|') + 1);
      ref.resize(ref.find('|'));
    }
    ASSERT_EQ(ref.substr(0, ref.find(':')), "bake.h5");
    const std::vector<int64_t> stored = datasetDims(h5, ref.substr(ref.find(':') + 1));
    ++heavyItems;
    if (selection.empty()) {
      EXPECT_EQ(stored, dims) << ref;
      return;
    }
    std::vector<std::vector<int64_t>> parts;  // start, stride, count, dataspace
    std::istringstream in(selection);
    for (std::string part; std::getline(in, part, ':');) parts.push_back(parseNumbers(part.c_str()));
    ASSERT_EQ(parts.size(), 4u) << selection;
    EXPECT_EQ(parts[3], stored) << ref;
    EXPECT_EQ(parts[2], dims) << ref;
    for (size_t a = 0; a < stored.size(); ++a)
      EXPECT_LT(parts[0][a] + (parts[2][a] - 1) * parts[1][a], stored[a]) << ref << '|' << selection;
  };

  tinyxml2::XMLDocument doc;
  ASSERT_EQ(doc.LoadFile(file("bake.xmf").c_str()), tinyxml2::XML_SUCCESS) << doc.ErrorStr();
  const tinyxml2::XMLElement* domain = doc.RootElement()->FirstChildElement("Domain");
  ASSERT_TRUE(domain);
  EXPECT_STREQ(doc.RootElement()->Attribute("Version"), "3.0");
  check(domain);
  EXPECT_EQ(heavyItems, (2 + 3) * 3);  // topology, geometry and vectors in every grid
  std::vector<std::pair<std::string, int>> collections;
  for (const auto* g = domain->FirstChildElement("Grid"); g; g = g->NextSiblingElement("Grid")) {
    EXPECT_STREQ(g->Attribute("CollectionType"), "Temporal");
    int steps = 0;
    for (const auto* step = g->FirstChildElement("Grid"); step; step = step->NextSiblingElement("Grid"), ++steps) {
      EXPECT_EQ(step->FirstChildElement("Time")->IntAttribute("Value", -1), steps);
      const auto* attribute = step->FirstChildElement("Attribute");
      ASSERT_TRUE(attribute);
      EXPECT_STREQ(attribute->Attribute("Name"), g->Attribute("Name"));
      EXPECT_STREQ(attribute->Attribute("AttributeType"), "Vector");
      const std::string ref = attribute->FirstChildElement("DataItem")->GetText();
      EXPECT_EQ(parseNumbers(ref.substr(ref.find('|') + 1).c_str())[0], steps) << ref;  // selection starts at vector i
    }
    collections.emplace_back(g->Attribute("Name"), steps);
  }
  EXPECT_EQ(collections, (std::vector<std::pair<std::string, int>>{{"modes", 2}, {"derivatives", 3}}));

  tinyxml2::XMLDocument meshOnly;
  ASSERT_EQ(meshOnly.LoadFile(file("mesh.xmf").c_str()), tinyxml2::XML_SUCCESS) << meshOnly.ErrorStr();
  heavyItems = 0;
  check(meshOnly.RootElement());
  EXPECT_EQ(heavyItems, 2);
  H5Fclose(h5);
  EXPECT_THROW(writeModesXdmf(file("bad.xmf"), "c:bake.h5", n, m, {}), std::runtime_error);
}
