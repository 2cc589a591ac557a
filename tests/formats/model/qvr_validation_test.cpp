// The .qvr reader refuses damaged and inconsistent files: every truncation, every byte flip, bad
// header and table fields (sizes near 2^64 included), bad layouts, versions, unknown and missing
// sections, and every MODEL_INFO or array inconsistency QVR.md lists. Expected messages come from
// QVR.md's layout of the default synthetic model: the section table at byte 64, MODEL_INFO at 384,
// ENERGY_COEFFICIENTS at 576, BASIS at 832, REST_POSITIONS at 1024, ..., 1568 bytes in all.
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "formats/model/qvr.h"
#include "formats/model/qvr_writer.h"
#include "tests/formats/model/qvr_test_files.h"

namespace quiver {
namespace {

using test::AlignedFile;
using test::parseError;
using test::RawSection;

const double kNaN = std::numeric_limits<double>::quiet_NaN();
const double kInf = std::numeric_limits<double>::infinity();
constexpr size_t kTable = 64, kFileSize = 1568;

std::string smallFile() { return formatModel(test::syntheticModel()); }

// `f` with `bytes` bytes at `at` set to `value` and every checksum recomputed.
std::string patched(std::string f, size_t at, uint64_t value, size_t bytes) {
  test::putLE(f, at, value, bytes);
  test::reseal(f);
  return f;
}

size_t entry(size_t index) { return kTable + 32 * index; }

#define EXPECT_REFUSED(bytes, fragment)                                                        \
  do {                                                                                         \
    const std::string error_ = parseError(bytes);                                              \
    EXPECT_NE(error_.find(fragment), std::string::npos) << "error: '" << error_ << "'";        \
  } while (0)

TEST(QvrValidation, TheSmallFileHasTheLayoutTheseTestsAssume) {
  const std::string f = smallFile();
  ASSERT_EQ(f.size(), kFileSize);
  EXPECT_EQ(parseError(f), "");
  EXPECT_EQ(test::getLE(f, entry(2) + 8, 8), 832u);  // BASIS
}

TEST(QvrValidation, EveryTruncationIsRefused) {
  const std::string f = smallFile();
  for (size_t n = 0; n < f.size(); ++n) EXPECT_NE(parseError(f.substr(0, n)), "") << "kept " << n << " bytes";
  EXPECT_REFUSED(f.substr(0, 63), "header at byte 0: the file has 63 bytes, fewer than the 64-byte header");
  EXPECT_REFUSED(f.substr(0, 1000), "file size 1568 does not match the 1000 bytes given");
}

TEST(QvrValidation, EverySingleByteChangeIsRefused) {
  const std::string f = smallFile();
  for (size_t at = 0; at < f.size(); ++at)
    for (unsigned mask : {0x01u, 0x80u, 0xffu}) {
      std::string g = f;
      g[at] = static_cast<char>(g[at] ^ mask);
      EXPECT_NE(parseError(g), "") << "byte " << at << " ^ " << mask;
    }
  std::string g = f;
  g[900] ^= 1;
  EXPECT_REFUSED(g, "BASIS at byte 832: checksum mismatch (stored 0x");
  g = f;
  g[1020] = 7;  // between BASIS (ends at 1012) and REST_POSITIONS
  EXPECT_REFUSED(g, "padding at byte 1020: not zero");
}

TEST(QvrValidation, ExtraBytesAreRefusedUnlessTheHeaderCountsThemAsZeroPadding) {
  const std::string f = smallFile();
  EXPECT_REFUSED(f + '\0', "file size 1568 does not match the 1569 bytes given");
  EXPECT_REFUSED(f + std::string(64, '\0'), "file size 1568 does not match the 1632 bytes given");
  EXPECT_EQ(parseError(patched(f + std::string(64, '\0'), 32, kFileSize + 64, 8)), "");
  EXPECT_REFUSED(patched(f + std::string(63, '\0') + 'x', 32, kFileSize + 64, 8), "padding at byte 1631: not zero");
}

TEST(QvrValidation, HeaderFieldsAreChecked) {
  const std::string f = smallFile();
  std::string g = f;
  g[0] = 'P';
  EXPECT_REFUSED(g, "not a .qvr file");
  g = f;
  g.replace(4, 2, "\n\n");  // what a CR-LF to LF conversion leaves
  EXPECT_REFUSED(g, "text mode");
  EXPECT_REFUSED(patched(f, 12, 0x04030201, 4), "header at byte 12: endianness tag");
  EXPECT_REFUSED(patched(f, 16, 0, 4), "header at byte 16: header size 0");
  EXPECT_REFUSED(patched(f, 16, 68, 4), "header size 68");
  EXPECT_REFUSED(patched(f, 16, 0xfffffff8u, 4), "header size 4294967288");
  EXPECT_REFUSED(patched(f, 20, 0, 4), "section count 0 is not in 1..64");
  EXPECT_REFUSED(patched(f, 20, 65, 4), "section count 65");
  EXPECT_REFUSED(patched(f, 20, 0xffffffffu, 4), "section count 4294967295");
  EXPECT_REFUSED(patched(f, 24, 60, 8), "section table at byte 60: offset is not a multiple of 8");
  EXPECT_REFUSED(patched(f, 24, 56, 8), "section table at byte 56: starts inside the 64-byte header");
  EXPECT_REFUSED(patched(f, 24, 1536, 8), "section table at byte 1536: runs past the end of the file (1568 bytes)");
  EXPECT_REFUSED(patched(f, 24, ~uint64_t{7}, 8), "runs past the end of the file (1568 bytes)");
  g = f;
  g[40] ^= 1;
  EXPECT_REFUSED(g, "header at byte 56: checksum mismatch");
  test::putLE(g, 56, fnv1a64(g.data(), 56), 8);  // a sealed header whose table checksum is wrong
  EXPECT_REFUSED(g, "section table at byte 64: checksum mismatch");
}

TEST(QvrValidation, SectionOffsetsAndSizesNearTwoToThe64AreRefused) {
  const std::string f = smallFile();
  const uint64_t max = std::numeric_limits<uint64_t>::max();
  const size_t basis = entry(2);
  EXPECT_REFUSED(patched(f, basis + 16, max, 8), "BASIS at byte 832: 18446744073709551615 bytes run past the end");
  EXPECT_REFUSED(patched(f, basis + 8, max - 63, 8), "bytes run past the end of the file (1568 bytes)");
  std::string g = patched(f, basis + 8, max - 63, 8);
  EXPECT_REFUSED(patched(g, basis + 16, 64, 8), "bytes run past the end");  // offset + size wraps to 0
  EXPECT_REFUSED(patched(f, basis + 8, 1600, 8), "BASIS at byte 1600: 180 bytes run past the end");
  EXPECT_REFUSED(patched(f, basis + 8, 840, 8), "BASIS at byte 840: offset is not a multiple of 64");
}

TEST(QvrValidation, OverlappingSectionsAreRefused) {
  const std::string f = smallFile();
  EXPECT_REFUSED(patched(f, entry(2) + 8, 768, 8), "BASIS at byte 768: overlaps ENERGY_COEFFICIENTS (which ends at byte 824)");
  EXPECT_REFUSED(patched(f, entry(0) + 8, 320, 8), "MODEL_INFO at byte 320: overlaps the section table");
  EXPECT_REFUSED(patched(f, entry(0) + 8, 0, 8), "overlaps the section table");
}

TEST(QvrValidation, VersionsWithAnotherMajorAreRefusedAndNewerMinorsLoad) {
  const std::vector<RawSection> sections = test::sectionsOf(test::syntheticModel());
  EXPECT_REFUSED(test::assemble(sections, {2, 0, ""}), "header at byte 8: version 2.0 is newer than this reader (1.x)");
  EXPECT_REFUSED(test::assemble(sections, {0, 9, ""}), "version 0.9 is older than this reader (1.x)");
  for (uint16_t minor : {1, 65535}) {
    // A later minor version: a longer header and a longer MODEL_INFO, both with data 1.0 ignores.
    std::vector<RawSection> longer = sections;
    longer[0].bytes += std::string(24, '\x5a');
    AlignedFile file(test::assemble(longer, {1, minor, std::string(64, '\x7f')}));
    ModelView view;
    std::string error;
    ASSERT_TRUE(file.parse(view, error)) << error;
    EXPECT_EQ(view.versionMinor, minor);
    EXPECT_EQ(view.info.r, 3u);
  }
}

TEST(QvrValidation, UnknownOptionalSectionsAreSkippedAndUnknownRequiredOnesRefused) {
  const std::vector<RawSection> sections = test::sectionsOf(test::syntheticModel());
  std::vector<RawSection> s = sections;
  s.insert(s.begin() + 3, RawSection{81, qvr::kOptionalSection | 6u, "from a later version"});
  s[2].flags = 0xfffffffe;  // reserved flag bits on a known section are ignored
  EXPECT_EQ(parseError(test::assemble(s)), "");
  s[3].flags = 6;
  EXPECT_REFUSED(test::assemble(s), "section type 81 at byte 1024: unknown section type without the optional flag");
  s = sections;
  s.push_back(s[7]);
  EXPECT_REFUSED(test::assemble(s), "a second EIGENVALUES section (the first is at byte 1472)");
  s = sections;
  s.push_back({81, 1, "x"});
  s.push_back({81, 1, "y"});
  EXPECT_REFUSED(test::assemble(s), "a second section type 81 section");
  const char* const names[] = {"MODEL_INFO", "ENERGY_COEFFICIENTS", "BASIS", "REST_POSITIONS",
                               "SURFACE_TRIANGLES", "VERTEX_MAP", "GRAVITY_PROJECTION", "EIGENVALUES"};
  for (size_t i = 0; i < 8; ++i) {
    s = sections;
    s.erase(s.begin() + i);
    EXPECT_REFUSED(test::assemble(s), std::string("missing required section ") + names[i]);
  }
  s = sections;
  s[0].bytes.resize(191);
  EXPECT_REFUSED(test::assemble(s), "MODEL_INFO at byte 384: size 191 is less than the 192 bytes of version 1.0");
}

TEST(QvrValidation, MisalignedBuffersAreRefused) {
  const std::string f = smallFile();
  for (size_t shift = 1; shift < 8; ++shift) {
    AlignedFile file(f, shift);
    ModelView view;
    std::string error;
    EXPECT_FALSE(file.parse(view, error));
    EXPECT_NE(error.find("is not 8-byte aligned"), std::string::npos) << error;
  }
}

// Contents the writer would refuse, assembled by hand: each must fail with the given message.
TEST(QvrValidation, ModelInfoAndArraysAreChecked) {
  struct Case {
    std::function<void(ModelContents&)> change;
    std::string message;
  };
  const std::vector<Case> cases = {
      {[](ModelContents& c) { c.info.r = 0; }, "MODEL_INFO at byte 384: r = 0 is not in 1..256"},
      {[](ModelContents& c) { c.info.r = 257; }, "r = 257 is not in 1..256"},
      {[](ModelContents& c) { c.info.r = 16; }, "r = 16 exceeds 3 x vertexCount 5"},
      {[](ModelContents& c) { c.info.vertexCount = 3; }, "vertexCount 3 is less than 4"},
      {[](ModelContents& c) { c.info.tetCount = 0; }, "tetCount is 0"},
      {[](ModelContents& c) { c.info.triangleCount = 3; }, "triangleCount 3 is less than 4"},
      {[](ModelContents& c) { c.info.fileVertexCount = 4; }, "fileVertexCount 4 is less than vertexCount 5"},
      {[](ModelContents& c) { c.info.basisPrecision = 16; }, "basisPrecision 16 is not 32 or 64"},
      {[](ModelContents& c) { c.info.coefficientLayout = 2; }, "coefficientLayout 2 is not 1"},
      {[](ModelContents& c) { c.info.materialIsUniform = 2; }, "materialIsUniform 2 is not 0 or 1"},
      {[](ModelContents& c) { c.info.youngsModulus = 0; }, "youngsModulus 0 is not finite and in (0, inf)"},
      {[](ModelContents& c) { c.info.youngsModulus = kInf; }, "youngsModulus inf"},
      {[](ModelContents& c) { c.info.youngsModulus = kNaN; }, "youngsModulus nan"},
      {[](ModelContents& c) { c.info.poissonRatio = 0.5; }, "poissonRatio 0.5 is not finite and in (-1, 0.5)"},
      {[](ModelContents& c) { c.info.poissonRatio = -1; }, "poissonRatio -1 is"},
      {[](ModelContents& c) { c.info.density = -1; }, "density -1 is"},
      {[](ModelContents& c) { c.info.totalMass = 0; }, "totalMass 0 is"},
      {[](ModelContents& c) { c.info.rayleighAlpha = -1e-300; }, "rayleighAlpha -1e-300 is not finite and in [0, inf)"},
      {[](ModelContents& c) { c.info.rayleighBeta = kNaN; }, "rayleighBeta nan"},
      {[](ModelContents& c) { c.info.timeStep = 0; }, "timeStep 0 is"},
      {[](ModelContents& c) { c.info.timeStep = 1e-300; }, "timeStep 1e-300 is not finite and in [1e-12, inf)"},
      {[](ModelContents& c) { c.info.bboxMax[1] += 1; }, "MODEL_INFO at byte 384: bounding box along axis 1"},
      {[](ModelContents& c) { c.info.bboxMin[2] -= 10; }, "bounding box along axis 2"},
      {[](ModelContents& c) { c.energy.pop_back(); },
       "ENERGY_COEFFICIENTS at byte 576: size 240 does not match 31 coefficients (r = 3) x 8 bytes"},
      {[](ModelContents& c) { c.energy[5] = kNaN; }, "ENERGY_COEFFICIENTS at byte 576: value 5 (byte 616) is not finite"},
      {[](ModelContents& c) { c.info.vertexCount = 6; }, "BASIS at byte 832: size 180 does not match 3 x 6 vertices x 3 x 4 bytes"},
      {[](ModelContents& c) { c.basis[7] = kInf; }, "BASIS at byte 832: value 7 (byte 860) is not finite"},
      {[](ModelContents& c) { c.restPositions[4] = -kInf; }, "REST_POSITIONS at byte 1024: value 4 (byte 1056) is not finite"},
      {[](ModelContents& c) { c.triangles.push_back(0); }, "SURFACE_TRIANGLES at byte 1152: size 76 does not match 3 x 6 triangles x 4 bytes"},
      {[](ModelContents& c) { c.triangles[4] = 5; }, "SURFACE_TRIANGLES at byte 1152: entry 4 (byte 1168) is 5, not below vertexCount 5"},
      {[](ModelContents& c) { c.triangles[5] = c.triangles[3]; }, "entry 5 (byte 1172) repeats vertex 1 of its group"},
      {[](ModelContents& c) { c.vertexMap[2] = 7; }, "VERTEX_MAP at byte 1280: entry 2 (byte 1288) is 7, not below fileVertexCount 7"},
      {[](ModelContents& c) { c.gravity[8] = kNaN; }, "GRAVITY_PROJECTION at byte 1344: value 8 (byte 1408) is not finite"},
      {[](ModelContents& c) { c.gravity.pop_back(); }, "size 64 does not match 3 x 3 x 8 bytes"},
      {[](ModelContents& c) { c.info.eigenvalueCount = 3; }, "EIGENVALUES at byte 1472: size 16 does not match 3 eigenvalues x 8 bytes"},
      {[](ModelContents& c) { c.eigenvalues[1] = kInf; }, "EIGENVALUES at byte 1472: value 1 (byte 1480) is not finite"},
      {[](ModelContents& c) { c.tets[6] = 9; }, "TETS at byte 1536: entry 6 (byte 1560) is 9, not below vertexCount 5"},
      {[](ModelContents& c) { c.tets[3] = c.tets[1]; }, "TETS at byte 1536: entry 3 (byte 1548) repeats vertex"},
      {[](ModelContents& c) { c.info.tetCount = 3; }, "TETS at byte 1536: size 32 does not match 4 x 3 tets x 4 bytes"},
  };
  for (const Case& k : cases) {
    ModelContents c = test::syntheticModel();
    k.change(c);
    EXPECT_REFUSED(test::assemble(test::sectionsOf(c)), k.message);
  }
}

} // namespace
// The FIDELITY section: the bake's report round-trips (NaN for "not measured" included) and every
// field is checked: counts, the size they imply, names, values.
// energyRisesAlongModes: every c_iiii > 0, else the first that is not, by its place in the file.
// The quartic (i, i, i, i) is found by enumerating QVR.md's sorted tuples in lexicographic order.
TEST(QvrValidation, AnEnergyThatFallsAlongAModeIsNamed) {
  test::Counts counts;
  counts.r = 4;
  counts.vertexCount = 6;
  ModelContents c = test::syntheticModel(counts);
  const size_t r = counts.r, quadratic = r * (r + 1) / 2, cubic = r * (r + 1) * (r + 2) / 6;
  std::vector<size_t> diagonal;  // index of (i, i, i, i) among the quartic tuples
  size_t index = 0;
  for (size_t i = 0; i < r; ++i)
    for (size_t j = i; j < r; ++j)
      for (size_t k = j; k < r; ++k)
        for (size_t l = k; l < r; ++l, ++index)
          if (i == l) diagonal.push_back(index);
  for (size_t i = 0; i < r; ++i) c.energy[quadratic + cubic + diagonal[i]] = 1.0 + i;
  const auto check = [](const ModelContents& contents) {
    test::AlignedFile file(formatModel(contents));
    ModelView view;
    std::string error;
    EXPECT_TRUE(file.parse(view, error)) << error;
    return energyRisesAlongModes(file.data(), view, error) ? std::string() : error;
  };
  EXPECT_EQ(check(c), "");
  const std::string f = formatModel(c);
  const size_t section = test::getLE(f, entry(1) + 8, 8);  // ENERGY_COEFFICIENTS, second in type order
  for (double value : {0.0, -0.0, -2.5}) {
    ModelContents falling = c;
    const size_t at = quadratic + cubic + diagonal[2];
    falling.energy[at] = value;
    falling.energy[quadratic + cubic + diagonal[3]] = -1;  // a later one is not reported
    EXPECT_EQ(check(falling), "ENERGY_COEFFICIENTS at byte " + std::to_string(section) + ": the coefficient of q2^4 (value " +
                                  std::to_string(at) + ", byte " + std::to_string(section + 8 * at) + ") is " +
                                  (value == -2.5 ? "-2.5" : std::signbit(value) ? "-0" : "0") +
                                  ", not positive: the energy falls without bound along mode 2, as no St.Venant-Kirchhoff energy does");
  }
}

TEST(QvrValidation, TheFidelityReportRoundTripsAndIsChecked) {
  ModelContents c = test::syntheticModel();
  c.fidelityCases = {{"own weight", 0.003, 0.4}, {"twist 30", kNaN, kNaN}};
  c.fidelityFrequencyErrors = {1e-3, -2e-4};
  const std::string f = formatModel(c);
  {
    test::AlignedFile file(f);
    ModelView view;
    std::string error;
    ASSERT_TRUE(file.parse(view, error)) << error;
    ASSERT_EQ(view.fidelityCaseCount, 2u);
    ASSERT_EQ(view.fidelityFrequencyCount, 2u);
    const ModelContents back = copyModel(view);
    EXPECT_EQ(back.fidelityCases[0].name, "own weight");
    EXPECT_EQ(back.fidelityCases[0].error, 0.003);
    EXPECT_EQ(back.fidelityCases[1].name, "twist 30");
    EXPECT_TRUE(std::isnan(back.fidelityCases[1].largestDisplacement));
    EXPECT_EQ(back.fidelityFrequencyErrors, c.fidelityFrequencyErrors);
    EXPECT_EQ(formatModel(back), f) << "a copy writes the same bytes";
  }
  // Where the section is: the last table entry (the writer puts sections in type order).
  const uint64_t count = test::getLE(f, 20, 4);
  const size_t at = test::getLE(f, entry(count - 1) + 8, 8);
  ASSERT_EQ(test::getLE(f, entry(count - 1), 4), uint64_t{qvr::kFidelity});
  EXPECT_REFUSED(patched(f, at, 17, 4), "FIDELITY at byte " + std::to_string(at) + ": case count 17 is above 16");
  EXPECT_REFUSED(patched(f, at + 4, 3, 4), "frequency count 3 is above the eigenvalue count 2");
  EXPECT_REFUSED(patched(f, at, 1, 4), "is not the 64 bytes of 1 cases and 2 frequencies");
  std::string unterminated = f;
  for (size_t k = 0; k < qvr::kFidelityNameSize; ++k) unterminated[at + 8 + k] = 'x';
  test::reseal(unterminated);
  EXPECT_REFUSED(unterminated, "case 0's name is not NUL-terminated");
  EXPECT_REFUSED(patched(f, at + 8, 0x07, 1), "case 0's name is not printable ASCII");
  EXPECT_REFUSED(patched(f, at + 8 + qvr::kFidelityNameSize, test::bitsOf(kInf), 8), "case 0 holds an infinite value");
  EXPECT_REFUSED(patched(f, at + 8 + 2 * qvr::kFidelityRecordSize, test::bitsOf(kNaN), 8), "frequency error 0 is not finite");
  c.fidelityCases[0].name = std::string(qvr::kFidelityNameSize, 'n');
  EXPECT_THROW(formatModel(c), std::runtime_error);
}

} // namespace quiver

namespace quiver {
namespace {

// The RIGID_BODY section: a free object's mass moments round-trip and are checked: the size r
// implies, finite values, the centre inside the box, symmetric second moments with mass along
// every axis.
TEST(QvrValidation, TheRigidBodyRoundTripsAndIsChecked) {
  ModelContents c = test::syntheticModel();
  const size_t r = c.info.r;
  c.rigidBody.assign(qvr::rigidBodySize(r), 0.25);
  for (int a = 0; a < 3; ++a) c.rigidBody[a] = 0.5 * (c.info.bboxMin[a] + c.info.bboxMax[a]);
  for (int ab = 0; ab < 9; ++ab) c.rigidBody[3 + ab] = ab % 4 == 0 ? 2.0 : 0.125;  // S0: diagonal 2, the rest 1/8
  const std::string f = formatModel(c);
  {
    test::AlignedFile file(f);
    ModelView view;
    std::string error;
    ASSERT_TRUE(file.parse(view, error)) << error;
    ASSERT_NE(view.rigidBody, nullptr);
    EXPECT_EQ(copyModel(view).rigidBody, c.rigidBody);
  }
  const uint64_t count = test::getLE(f, 20, 4);
  const size_t at = test::getLE(f, entry(count - 1) + 8, 8);
  ASSERT_EQ(test::getLE(f, entry(count - 1), 4), uint64_t{qvr::kRigidBody});
  const std::string section = "RIGID_BODY at byte " + std::to_string(at) + ": ";
  EXPECT_REFUSED(patched(f, at + 8 * 20, test::bitsOf(kNaN), 8), section + "value 20 (byte " + std::to_string(at + 160) + ") is not finite");
  EXPECT_REFUSED(patched(f, at, test::bitsOf(c.info.bboxMax[0] + 1), 8), section + "the centre of mass lies outside the bounding box");
  EXPECT_REFUSED(patched(f, at + 8 * 7, test::bitsOf(-1.0), 8), section + "second moment 11 is not positive");
  EXPECT_REFUSED(patched(f, at + 8 * 4, test::bitsOf(0.5), 8), section + "the second moments are not symmetric");
  c.rigidBody.pop_back();
  EXPECT_THROW(formatModel(c), std::runtime_error);
}

TEST(QvrValidation, TheRenderMeshRoundTripsAndIsChecked) {
  test::Counts counts;
  counts.withTets = true;
  ModelContents c = test::syntheticModel(counts);
  const size_t r = c.info.r;
  ModelContents::RenderMesh& m = c.render;
  m.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  m.triangles = {0, 1, 2};
  m.tets = {0, 0, 1};
  m.weights = {0.25f, 0.25f, 0.25f, 0.25f, 1, 0, 0, 0, -0.5f, 0.5f, 0.5f, 0.5f};
  m.uvs = {0, 0, 1, 0, 0, 1};
  m.basis.assign(9 * r, 0.125f);
  const std::string f = formatModel(c);
  {
    test::AlignedFile file(f);
    ModelView view;
    std::string error;
    ASSERT_TRUE(file.parse(view, error)) << error;
    ASSERT_EQ(view.renderVertexCount, 3u);
    EXPECT_EQ(view.renderNormals, nullptr);
    const ModelContents back = copyModel(view);
    EXPECT_EQ(back.render.weights, m.weights);
    EXPECT_EQ(back.render.uvs, m.uvs);
    EXPECT_EQ(back.render.basis, m.basis);
  }
  const uint64_t count = test::getLE(f, 20, 4);
  const size_t at = test::getLE(f, entry(count - 1) + 8, 8);
  ASSERT_EQ(test::getLE(f, entry(count - 1), 4), uint64_t{qvr::kRenderMesh});
  const std::string section = "RENDER_MESH at byte " + std::to_string(at) + ": ";
  const size_t triangles = at + 16 + 36, tetsAt = triangles + 12, weights = tetsAt + 12;
  EXPECT_REFUSED(patched(f, at + 8, 4, 4), section + "unknown flags or a non-zero reserved word");
  EXPECT_REFUSED(patched(f, at, 4, 4), section + "size");
  EXPECT_REFUSED(patched(f, triangles + 4, 0, 4), section + "triangle entry 1 repeats a vertex of its triangle");
  EXPECT_REFUSED(patched(f, triangles + 8, 3, 4), section + "triangle entry 2 (byte " + std::to_string(triangles + 8) + ") is 3, not below 3");
  EXPECT_REFUSED(patched(f, tetsAt, c.info.tetCount, 4), section + "tet entry 0");
  float bad = 0.5f;
  uint32_t bits;
  std::memcpy(&bits, &bad, 4);
  EXPECT_REFUSED(patched(f, weights + 16, bits, 4), section + "vertex 1's weights are not those of a point in or near its tet");
  EXPECT_REFUSED(patched(f, weights + 16 * 3 + 24 + 4, 0x7fc00000u, 4), section + "render basis value 1");
  c.tets.clear();
  EXPECT_THROW(formatModel(c), std::runtime_error);  // a render mesh needs the tets
}

} // namespace
} // namespace quiver
