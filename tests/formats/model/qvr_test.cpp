// The .qvr model format: the checksum, the monomial order, bit-exact round trips through the
// writer, files assembled by hand from QVR.md, the worked size example of QVR.md, and the seed files
// written by the independent Python implementation in tests/fuzz/make_seeds.py.
#include <cstdint>
#include <fstream>
#include <iterator>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <Eigen/Core>

#include "formats/model/fnv1a.h"
#include "formats/model/qvr.h"
#include "formats/model/qvr_writer.h"
#include "tests/formats/model/qvr_test_files.h"
#include "tests/support/test_support.h"

namespace quiver {
namespace {

using test::AlignedFile;
using test::Counts;

// Where two byte strings first differ, for readable failures on whole files.
std::string difference(const std::string& a, const std::string& b) {
  if (a == b) return "";
  size_t i = 0;
  while (i < a.size() && i < b.size() && a[i] == b[i]) ++i;
  return "sizes " + std::to_string(a.size()) + " and " + std::to_string(b.size()) + ", first difference at byte " +
         std::to_string(i);
}

template <class T>
std::string bytesAt(const T* p, size_t count) {
  return test::arrayBytes(std::vector<T>(p, p + count));
}

// Checks bit by bit that `v` holds `c` (the basis rounded to float32 when stored so).
void expectHolds(const ModelView& v, const ModelContents& c) {
  EXPECT_EQ(test::infoBytes(v.info), test::infoBytes(c.info));
  const size_t r = c.info.r, n = c.info.vertexCount;
  EXPECT_EQ(bytesAt(v.energy, energyCoefficientCount(r)), test::arrayBytes(c.energy));
  if (c.info.basisPrecision == 32) {
    ASSERT_NE(v.basis32, nullptr);
    EXPECT_EQ(v.basis64, nullptr);
    EXPECT_EQ(bytesAt(v.basis32, 3 * n * r), test::arrayBytes(std::vector<float>(c.basis.begin(), c.basis.end())));
  } else {
    ASSERT_NE(v.basis64, nullptr);
    EXPECT_EQ(v.basis32, nullptr);
    EXPECT_EQ(bytesAt(v.basis64, 3 * n * r), test::arrayBytes(c.basis));
  }
  EXPECT_EQ(bytesAt(v.restPositions, 3 * n), test::arrayBytes(c.restPositions));
  EXPECT_EQ(bytesAt(v.triangles, 3 * c.info.triangleCount), test::arrayBytes(c.triangles));
  EXPECT_EQ(bytesAt(v.vertexMap, n), test::arrayBytes(c.vertexMap));
  EXPECT_EQ(bytesAt(v.gravity, 3 * r), test::arrayBytes(c.gravity));
  EXPECT_EQ(bytesAt(v.eigenvalues, c.info.eigenvalueCount), test::arrayBytes(c.eigenvalues));
  if (c.tets.empty()) {
    EXPECT_EQ(v.tets, nullptr);
  } else {
    ASSERT_NE(v.tets, nullptr);
    EXPECT_EQ(bytesAt(v.tets, 4 * c.info.tetCount), test::arrayBytes(c.tets));
  }
}

std::vector<Counts> variants() {
  std::vector<Counts> all;
  for (uint32_t precision : {32u, 64u})
    for (bool tets : {true, false}) {
      Counts k;
      k.basisPrecision = precision;
      k.withTets = tets;
      all.push_back(k);
    }
  return all;
}

std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

TEST(Fnv1a, MatchesPublishedTestVectors) {
  EXPECT_EQ(fnv1a64("", 0), 0xcbf29ce484222325ull);
  EXPECT_EQ(fnv1a64("a", 1), 0xaf63dc4c8601ec8cull);
  EXPECT_EQ(fnv1a64("foobar", 6), 0x85944171f73967e8ull);
  EXPECT_EQ(fnv1a64("bar", 3, fnv1a64("foo", 3)), 0x85944171f73967e8ull);
}

static_assert(monomialIndex4(3, 2, 2, 2, 2) == monomialCount4(3) - 1, "the helpers are constexpr");

TEST(QvrMonomials, IndicesEnumerateSortedTuplesInLexicographicOrder) {
  for (uint32_t r = 1; r <= 7; ++r) {
    SCOPED_TRACE("r = " + std::to_string(r));
    size_t next2 = 0, next3 = 0, next4 = 0;
    for (uint32_t i = 0; i < r; ++i)
      for (uint32_t j = i; j < r; ++j) {
        EXPECT_EQ(monomialIndex2(r, i, j), next2++);
        for (uint32_t k = j; k < r; ++k) {
          // (i, j, k) tuples come in lexicographic order here as well: k runs fastest.
          EXPECT_EQ(monomialIndex3(r, i, j, k), next3++);
          for (uint32_t l = k; l < r; ++l) EXPECT_EQ(monomialIndex4(r, i, j, k, l), next4++);
        }
      }
    EXPECT_EQ(monomialCount2(r), next2);
    EXPECT_EQ(monomialCount3(r), next3);
    EXPECT_EQ(monomialCount4(r), next4);
    EXPECT_EQ(energyCoefficientCount(r), next2 + next3 + next4);
  }
  // The counts DESIGN.md gives for r = 30, and the largest r.
  EXPECT_EQ(monomialCount2(30), 465u);
  EXPECT_EQ(monomialCount3(30), 4960u);
  EXPECT_EQ(monomialCount4(30), 40920u);
  EXPECT_EQ(monomialCount4(256), 183181376u);
}

TEST(Qvr, RoundTripIsBitExact) {
  for (const Counts& k : variants()) {
    SCOPED_TRACE("basis float" + std::to_string(k.basisPrecision) + (k.withTets ? " with tets" : " without tets"));
    const ModelContents c = test::syntheticModel(k);
    const std::string bytes = formatModel(c);
    AlignedFile file(bytes);
    ModelView view;
    std::string error;
    ASSERT_TRUE(file.parse(view, error)) << error;
    EXPECT_EQ(view.versionMinor, 0);
    expectHolds(view, c);
    EXPECT_EQ(difference(formatModel(copyModel(view)), bytes), "");
  }
}

TEST(Qvr, HandAssembledFileParsesAndEqualsTheWritersBytes) {
  for (const Counts& k : variants()) {
    SCOPED_TRACE("basis float" + std::to_string(k.basisPrecision) + (k.withTets ? " with tets" : " without tets"));
    const ModelContents c = test::syntheticModel(k);
    const std::string bytes = test::assemble(test::sectionsOf(c));
    AlignedFile file(bytes);
    ModelView view;
    std::string error;
    ASSERT_TRUE(file.parse(view, error)) << error;
    expectHolds(view, c);
    EXPECT_EQ(difference(formatModel(c), bytes), "");
  }
}

TEST(Qvr, FileSizeMatchesTheWorkedExampleOfTheSpec) {
  Counts k;
  k.r = 30;
  k.vertexCount = 5000;
  k.tetCount = 20000;
  k.triangleCount = 4000;
  k.eigenvalueCount = 30;
  EXPECT_EQ(formatModel(test::syntheticModel(k)).size(), 2680448u);
  k.basisPrecision = 64;
  EXPECT_EQ(formatModel(test::syntheticModel(k)).size(), 4480448u);
}

TEST(Qvr, WriteModelFileWritesTheFormattedBytes) {
  const ModelContents c = test::syntheticModel();
  const std::string path = test::tempDir("qvr_write") + "/model.qvr";
  writeModelFile(path, c);
  EXPECT_EQ(difference(readFile(path), formatModel(c)), "");
}

TEST(Qvr, WriterRefusesInconsistentContents) {
  ModelContents c = test::syntheticModel();
  c.basis.pop_back();
  try {
    formatModel(c);
    ADD_FAILURE() << "formatModel accepted a basis one entry short";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("BASIS"), std::string::npos) << e.what();
  }
  c = test::syntheticModel();
  c.info.poissonRatio = 0.5;
  EXPECT_THROW(formatModel(c), std::runtime_error);
}

// make_seeds.py writes these from QVR.md with Python's struct module, independently of the C++
// writer: r = 2, one tet (4 vertices, 4 triangles), 2 eigenvalues. newer_minor.qvr holds the
// model of float32_tets.qvr as a version 1.1 file with a longer header, a longer MODEL_INFO and
// an unknown optional section.
TEST(Qvr, SeedsOfTheIndependentPythonWriterParse) {
  const std::string folder = test::asset("../fuzz/seeds/qvr/");
  const std::string f32 = readFile(folder + "float32_tets.qvr"), f64 = readFile(folder + "float64.qvr"),
                    newer = readFile(folder + "newer_minor.qvr");
  if (f32.empty() || f64.empty() || newer.empty()) GTEST_SKIP() << "no .qvr seeds in " << folder;
  for (const std::string* bytes : {&f32, &f64, &newer}) {
    AlignedFile file(*bytes);
    ModelView view;
    std::string error;
    ASSERT_TRUE(file.parse(view, error)) << error;
    EXPECT_EQ(view.info.r, 2u);
    EXPECT_EQ(view.info.vertexCount, 4u);
    EXPECT_EQ(view.info.triangleCount, 4u);
    EXPECT_EQ(view.info.eigenvalueCount, 2u);
    EXPECT_EQ(view.info.basisPrecision, bytes == &f64 ? 64u : 32u);
    EXPECT_EQ(view.tets == nullptr, bytes == &f64);
    EXPECT_EQ(view.versionMinor, bytes == &newer ? 1 : 0);
    EXPECT_EQ(difference(formatModel(copyModel(view)), bytes == &newer ? f32 : *bytes), "");
  }
  // A render mesh written from QVR.md alone: read as written, and the C++ writer gives the same bytes.
  const std::string render = readFile(folder + "render_mesh.qvr");
  ASSERT_FALSE(render.empty());
  AlignedFile file(render);
  ModelView view;
  std::string error;
  ASSERT_TRUE(file.parse(view, error)) << error;
  EXPECT_EQ(view.renderVertexCount, 3u);
  EXPECT_EQ(view.renderTriangleCount, 1u);
  ASSERT_NE(view.renderNormals, nullptr);
  ASSERT_NE(view.renderUVs, nullptr);
  EXPECT_EQ(view.renderWeights[8], -0.5f);
  EXPECT_EQ(view.renderBasis[5], 0.05f);
  EXPECT_EQ(difference(formatModel(copyModel(view)), render), "");
}

// MODAL_ROTATIONS (type 10) is written with the optional flag, read back exactly, and a reader that
// did not know the type would skip it: the flag bit is set in its table entry.
TEST(Qvr, ModalRotationsRoundTripAsAnOptionalSection) {
  ModelContents c = test::syntheticModel();
  c.rotations = test::values(3 * size_t{c.info.vertexCount} * c.info.r, 99, 0.5, false);
  const std::string bytes = formatModel(c);
  const std::vector<unsigned char> buffer(bytes.begin(), bytes.end());
  ModelView view;
  std::string error;
  ASSERT_TRUE(parseModel(buffer.data(), buffer.size(), view, error)) << error;
  ASSERT_NE(view.rotations, nullptr);
  EXPECT_EQ(0, std::memcmp(view.rotations, c.rotations.data(), c.rotations.size() * sizeof(double)));
  uint64_t table = 0;
  uint32_t count = 0;
  std::memcpy(&table, &bytes[qvr::kTableOffsetAt], 8);
  std::memcpy(&count, &bytes[qvr::kSectionCountAt], 4);
  bool found = false;
  for (uint32_t s = 0; s < count; ++s) {
    uint32_t type = 0, flags = 0;
    std::memcpy(&type, &bytes[table + s * qvr::kSectionEntrySize + qvr::kTypeAt], 4);
    std::memcpy(&flags, &bytes[table + s * qvr::kSectionEntrySize + qvr::kFlagsAt], 4);
    if (type == qvr::kModalRotations) found = (flags & qvr::kOptionalSection) != 0;
  }
  EXPECT_TRUE(found);
  c.rotations.pop_back();
  EXPECT_THROW(formatModel(c), std::runtime_error);  // wrong size: refused like any other section
  EXPECT_EQ(copyModel(view).rotations.size(), 3 * size_t{c.info.vertexCount} * c.info.r);
}

TEST(Qvr, EverySectionTypeHasOneNameAndUnknownOnesSayTheirNumber) {
  EXPECT_EQ(qvr::sectionName(qvr::kModelInfo), "MODEL_INFO");
  EXPECT_EQ(qvr::sectionName(qvr::kModalRotations), "MODAL_ROTATIONS");
  for (uint32_t t = 1; t <= qvr::kLastKnownType; ++t) EXPECT_EQ(qvr::sectionName(t).find("type"), std::string::npos) << t;
  EXPECT_EQ(qvr::sectionName(qvr::kLastKnownType + 1), "section type " + std::to_string(qvr::kLastKnownType + 1));
  EXPECT_EQ(qvr::sectionName(0), "section type 0");
}

// The energy w^T G w of w = [q; q_j q_k (j <= k)] equals the folded monomials summed term by term.
TEST(Qvr, TheGramMatrixFoldsIntoTheEnergyMonomials) {
  const int r = 3, P = r * (r + 1) / 2, N = r + P;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  Eigen::MatrixXd B(7, N);
  for (int i = 0; i < B.size(); ++i) B.data()[i] = u(rng);
  const Eigen::MatrixXd G = B.transpose() * B;
  const std::vector<double> c = energyCoefficientsFromGram(G.data(), N, r);
  ASSERT_EQ(c.size(), static_cast<size_t>(monomialCount2(r) + monomialCount3(r) + monomialCount4(r)));
  for (int trial = 0; trial < 5; ++trial) {
    Eigen::VectorXd q(r), w(N);
    for (int i = 0; i < r; ++i) w[i] = q[i] = u(rng);
    for (int j = 0, p = r; j < r; ++j)
      for (int k = j; k < r; ++k) w[p++] = q[j] * q[k];
    double sum = 0;
    for (int i = 0; i < r; ++i)
      for (int j = i; j < r; ++j) {
        sum += c[monomialIndex2(r, i, j)] * q[i] * q[j];
        for (int k = j; k < r; ++k) {
          sum += c[monomialCount2(r) + monomialIndex3(r, i, j, k)] * q[i] * q[j] * q[k];
          for (int l = k; l < r; ++l)
            sum += c[monomialCount2(r) + monomialCount3(r) + monomialIndex4(r, i, j, k, l)] * q[i] * q[j] * q[k] * q[l];
        }
      }
    EXPECT_NEAR(sum, w.dot(G * w), 1e-12 * std::abs(w.dot(G * w)) + 1e-14);
  }
}

} // namespace
} // namespace quiver
