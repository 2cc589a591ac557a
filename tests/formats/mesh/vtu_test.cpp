// VTK XML .vtu reader and writer: hand-written ascii files, every binary encoding (built here with
// zlib's compress() and a base64 encoder of the test's own), write-read round trips and bad input.
#include <zlib.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstring>
#include <functional>
#include <random>

#include <gtest/gtest.h>

#include "formats/mesh/byte_cursor.h"
#include "formats/mesh/read_mesh.h"
#include "formats/mesh/write_mesh.h"
#include "tests/formats/mesh/text_mesh_test_support.h"

namespace quiver {
namespace {

using test::lineOf;
using test::meshErrorOf;
using test::replaced;

// Two pieces: a tet and a triangle over 5 points, then a tet over its own 4 points.
const std::string kAscii = R"(<?xml version="1.0"?>
<VTKFile type="UnstructuredGrid" version="0.1" byte_order="LittleEndian">
  <UnstructuredGrid>
    <Piece NumberOfPoints="5" NumberOfCells="2">
      <PointData>
        <DataArray type="Float32" Name="u" format="ascii">1 2 3 4 5</DataArray>
      </PointData>
      <CellData>
        <DataArray type="Float64" Name="pressure" format="ascii">0.5 1.5</DataArray>
        <DataArray type="Int32" Name="gmsh:physical" format="ascii">-3 4</DataArray>
      </CellData>
      <Points>
        <DataArray type="Float64" NumberOfComponents="3" format="ascii">
          0 0 0  1 0 0  0 1 0
          0 0 1  0.1 0.2 0.3
        </DataArray>
      </Points>
      <Cells>
        <DataArray type="Int32" Name="connectivity" format="ascii">0 1 2 3 4 1 2</DataArray>
        <DataArray type="Int32" Name="offsets" format="ascii">4 7</DataArray>
        <DataArray type="UInt8" Name="types" format="ascii">10 5</DataArray>
      </Cells>
    </Piece>
    <Piece NumberOfPoints="4" NumberOfCells="1">
      <Points>
        <DataArray type="Float32" NumberOfComponents="3" format="ascii">2 0 0 3 0 0 2 1 0 2 0 1</DataArray>
      </Points>
      <Cells>
        <DataArray type="Int64" Name="connectivity" format="ascii">0 1 2 3</DataArray>
        <DataArray type="Int64" Name="offsets" format="ascii">4</DataArray>
        <DataArray type="Int64" Name="types" format="ascii">10</DataArray>
      </Cells>
    </Piece>
  </UnstructuredGrid>
</VTKFile>
)";

std::string errorOf(const std::string& text) {
  return meshErrorOf([&] { parseVtu(text, "bad.vtu"); });
}

// `message` contains each of `parts`.
void expectMessage(const std::string& message, std::initializer_list<std::string> parts) {
  for (const std::string &part : parts)
    EXPECT_NE(message.find(part), std::string::npos) << "'" << part << "' not in '" << message << "'";
}

TEST(VtuRead, AsciiPiecesAreConcatenated) {
  const RawMesh raw = parseVtu(kAscii, "two.vtu");
  const TetMesh& mesh = raw.mesh;
  ASSERT_EQ(mesh.vertexCount(), 9);
  EXPECT_EQ(mesh.vertices[4], Eigen::Vector3d(0.1, 0.2, 0.3));
  EXPECT_EQ(mesh.vertices[8], Eigen::Vector3d(2, 0, 1));
  EXPECT_EQ(mesh.tets, (std::vector<Tet>{{0, 1, 2, 3}, {5, 6, 7, 8}}));
  EXPECT_EQ(mesh.tetRegion, (std::vector<int>{-3, 0}));  // the second piece has no region array
  EXPECT_EQ(raw.source.positionKind, SourcePositionKind::Record);
  EXPECT_EQ(raw.source.tetPosition, (std::vector<int64_t>{0, 2}));
  EXPECT_EQ(raw.source.tetFileId, (std::vector<int64_t>{0, 2}));
  EXPECT_EQ(raw.source.vertexFileId, (std::vector<int64_t>{0, 1, 2, 3, 4, 5, 6, 7, 8}));
  EXPECT_EQ(raw.report.skippedCells, 1);
  ASSERT_EQ(raw.report.warnings.size(), 1u);
  expectMessage(raw.report.warnings[0], {"two.vtu", "1 VTK_TRIANGLE"});
}

// ---- A reference encoder for the binary forms -------------------------------------------------

std::string base64(std::string_view bytes) {
  static const char kDigits[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (size_t i = 0; i < bytes.size(); i += 3) {
    uint32_t group = 0;
    const size_t n = std::min<size_t>(3, bytes.size() - i);
    for (size_t k = 0; k < 3; ++k) group = group << 8 | (k < n ? static_cast<unsigned char>(bytes[i + k]) : 0u);
    for (size_t k = 0; k < 4; ++k) out += k <= n ? kDigits[group >> (18 - 6 * k) & 63] : '=';
  }
  return out;
}

enum class Placement { Inline, AppendedRaw, AppendedBase64 };

struct Layout {
  Placement placement = Placement::Inline;
  bool bigEndian = false, header64 = false, compressed = false;
  std::function<void(std::vector<uint64_t>&)> tamper;  // applied to the Points array's header words
};

// Builds .vtu files the way VTK lays them out, for a layout.
class VtuBuilder {
public:
  explicit VtuBuilder(Layout layout) : layout_(std::move(layout)) {}

  template <class T>
  std::string array(const char* type, const std::string& name, int components, const std::vector<T>& values) {
    std::string raw;
    for (T v : values) put(raw, v);
    std::vector<uint64_t> header;
    std::vector<std::string> blocks;
    if (layout_.compressed) {  // blocks of 24 bytes, the last one partial
      const size_t blockSize = 24;
      for (size_t at = 0; at < raw.size(); at += blockSize) {
        const std::string block = raw.substr(at, blockSize);
        std::string packed(compressBound(block.size()), '\0');
        uLongf length = packed.size();
        EXPECT_EQ(compress(reinterpret_cast<Bytef*>(packed.data()), &length,
                           reinterpret_cast<const Bytef*>(block.data()), block.size()), Z_OK);
        blocks.push_back(packed.substr(0, length));
      }
      header = {blocks.size(), blockSize, raw.size() % blockSize};
      for (const std::string& b : blocks) header.push_back(b.size());
    } else {
      header = {raw.size()};
      blocks = {raw};
    }
    if (name == "Points" && layout_.tamper) layout_.tamper(header);
    std::string head, data;
    for (uint64_t w : header) layout_.header64 ? put(head, w) : put(head, static_cast<uint32_t>(w));
    for (const std::string& b : blocks) data += b;
    // VTK encodes a compressed array's header and blocks separately, an uncompressed one in one go.
    const std::string encoded = layout_.compressed ? base64(head) + base64(data) : base64(head + data);
    std::string e = std::string("<DataArray type=\"") + type + "\" Name=\"" + name + "\" NumberOfComponents=\"" +
                    std::to_string(components) + "\" format=\"";
    if (layout_.placement == Placement::Inline) return e + "binary\">\n" + encoded + "\n</DataArray>\n";
    e += "appended\" offset=\"" + std::to_string(appended_.size()) + "\"/>\n";
    appended_ += layout_.placement == Placement::AppendedRaw ? head + data : encoded;
    return e;
  }

  std::string file(const std::string& piece) const {
    std::string s =
        std::string("<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"") +
        (layout_.bigEndian ? "BigEndian" : "LittleEndian") + "\" header_type=\"" +
        (layout_.header64 ? "UInt64" : "UInt32") + "\"" +
        (layout_.compressed ? " compressor=\"vtkZLibDataCompressor\"" : "") + ">\n<UnstructuredGrid>\n" + piece +
        "</UnstructuredGrid>\n";
    if (layout_.placement != Placement::Inline)
      s += std::string("<AppendedData encoding=\"") + (layout_.placement == Placement::AppendedRaw ? "raw" : "base64") +
           "\">\n  _" + appended_ + "\n</AppendedData>\n";
    return s + "</VTKFile>\n";
  }

private:
  template <class T>
  void put(std::string& out, T v) const {
    char raw[sizeof(T)];
    std::memcpy(raw, &v, sizeof(T));
    if (hostIsLittleEndian() == layout_.bigEndian) std::reverse(raw, raw + sizeof(T));
    out.append(raw, sizeof(T));
  }

  Layout layout_;
  std::string appended_;
};

// Six points; a tet, a triangle and a tet, with regions -4, 5, 600 and a point array to skip.
const std::vector<double> kPoints = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0.1, 0.2, 0.3, -1e-300, 7, 1e10};

std::string binaryFile(const Layout &layout,
                       const std::vector<int32_t> &connectivity = {0, 1, 2, 3, 4, 2, 1, 2, 3, 5}) {
  VtuBuilder b(layout);
  std::string piece = "<Piece NumberOfPoints=\"6\" NumberOfCells=\"3\">\n<PointData>\n";
  piece += b.array("Float32", "u", 3, std::vector<float>(18, 0.5f));
  piece += "</PointData>\n<CellData>\n";
  piece += b.array("Int16", "CellEntityIds", 1, std::vector<int16_t>{-4, 5, 600});
  piece += "</CellData>\n<Points>\n";
  piece += b.array("Float64", "Points", 3, kPoints);
  piece += "</Points>\n<Cells>\n";
  piece += b.array("Int32", "connectivity", 1, connectivity);
  piece += b.array("UInt64", "offsets", 1, std::vector<uint64_t>{4, 6, 10});
  piece += b.array("UInt8", "types", 1, std::vector<uint8_t>{10, 5, 10});
  return b.file(piece + "</Cells>\n</Piece>\n");
}

std::string describe(const Layout& l) {
  const char* placement[] = {"inline base64", "appended raw", "appended base64"};
  return std::string(placement[static_cast<int>(l.placement)]) + (l.bigEndian ? ", big-endian" : ", little-endian") +
         (l.header64 ? ", UInt64 header" : ", UInt32 header") + (l.compressed ? ", zlib" : "");
}

std::vector<Layout> allLayouts() {
  std::vector<Layout> layouts;
  for (Placement p : {Placement::Inline, Placement::AppendedRaw, Placement::AppendedBase64})
    for (bool bigEndian : {false, true})
      for (bool header64 : {false, true})
        for (bool compressed : {false, true}) layouts.push_back({p, bigEndian, header64, compressed, {}});
  return layouts;
}

TEST(VtuRead, EveryBinaryLayoutReadsTheSame) {
  for (const Layout& layout : allLayouts()) {
    SCOPED_TRACE(describe(layout));
    const RawMesh raw = parseVtu(binaryFile(layout), "binary.vtu");
    ASSERT_EQ(raw.mesh.vertexCount(), 6);
    for (int v = 0; v < 6; ++v)
      EXPECT_EQ(raw.mesh.vertices[v], Eigen::Vector3d(kPoints[3 * v], kPoints[3 * v + 1], kPoints[3 * v + 2]));
    EXPECT_EQ(raw.mesh.tets, (std::vector<Tet>{{0, 1, 2, 3}, {1, 2, 3, 5}}));
    EXPECT_EQ(raw.mesh.tetRegion, (std::vector<int>{-4, 600}));
    EXPECT_EQ(raw.source.tetPosition, (std::vector<int64_t>{0, 2}));
    EXPECT_EQ(raw.report.skippedCells, 1);
  }
}

TEST(VtuBadInput, PointIndexOutOfRange) {
  for (const Layout& layout : allLayouts()) {
    SCOPED_TRACE(describe(layout));
    const std::string text = binaryFile(layout, {0, 1, 2, 3, 4, 2, 1, 2, 3, 6});
    expectMessage(meshErrorOf([&] { parseVtu(text, "bad.vtu"); }),
                  {"bad.vtu:" + std::to_string(lineOf(text, "Name=\"connectivity\"")) + ": DataArray 'connectivity'",
                   "cell 2: point index 6 is out of range [0, 6)"});
  }
}

TEST(VtuBadInput, CorruptBase64) {
  Layout layout;
  std::string text = binaryFile(layout);
  const size_t data = text.find('\n', text.find("Name=\"Points\"")) + 1;
  text[data + 5] = '!';
  expectMessage(errorOf(text), {"bad.vtu:" + std::to_string(lineOf(text, "Name=\"Points\"")) + ": DataArray 'Points'",
                                "invalid base64 character '!' at character 6"});
  layout.placement = Placement::AppendedBase64;
  text = binaryFile(layout);
  const size_t offset = std::stoul(text.substr(text.find("offset=\"", text.find("Name=\"Points\"")) + 8));
  const size_t at = text.find('_', text.find("<AppendedData")) + 1 + offset + 2;
  text[at] = '*';
  expectMessage(errorOf(text), {"DataArray 'Points'", "invalid base64 character '*' at byte " + std::to_string(at)});
}

TEST(VtuBadInput, LyingCompressionHeader) {
  for (Placement placement : {Placement::Inline, Placement::AppendedRaw}) {
    Layout layout{placement, false, true, true, {}};
    SCOPED_TRACE(describe(layout));
    const auto errorWith = [&](std::function<void(std::vector<uint64_t>&)> tamper) {
      layout.tamper = std::move(tamper);
      return errorOf(binaryFile(layout));
    };
    // The Points array: 144 bytes in 6 blocks of 24; header words are blocks, size, last, sizes...
    expectMessage(errorWith([](auto& h) { h[3 + 5] += 1000; }), {"DataArray 'Points'", "block 5", "runs past the end"});
    expectMessage(errorWith([](auto& h) { h[3] += 1, h[4] -= 1; }), {"DataArray 'Points'", "block 1 does not inflate"});
    expectMessage(errorWith([](auto& h) { h[1] = 48; }), {"DataArray 'Points'", "6 blocks of 48 bytes", "needs 144"});
    expectMessage(errorWith([](auto& h) { h[2] = 12; }), {"DataArray 'Points'", "(last 12), 132 bytes in all"});
    expectMessage(errorWith([](auto& h) { h[1] = 1, h[2] = 0, h[0] = 144; }), {"DataArray 'Points'"});
    expectMessage(errorWith([](auto& h) { h[0] = uint64_t(1) << 40; }), {"DataArray 'Points'", "1099511627776 blocks"});
    expectMessage(errorWith([](auto& h) { h[1] = h[2] = 1u << 30, h[0] = 1; }), {"1 blocks of 1073741824 bytes"});
    expectMessage(errorWith([](auto& h) { h = {1, 144, 0, h[3]}; }), {"block 0 does not inflate to the 144 bytes"});
    // A huge array whose header claims more output than zlib could make of the compressed bytes
    // fails before anything is allocated for it.
    layout.tamper = [](auto& h) { h = {1, 48000000000, 0, h[3]}; };
    expectMessage(errorOf(replaced(binaryFile(layout), "NumberOfPoints=\"6\"", "NumberOfPoints=\"2000000000\"")),
                  {"DataArray 'Points'", "cannot inflate to 48000000000 bytes"});
  }
}

TEST(VtuBadInput, SizesAndOffsets) {
  Layout layout{Placement::AppendedRaw, false, false, false, {}};
  std::string text = binaryFile(layout);
  const size_t pointsOffset = text.find("offset=\"", text.find("Name=\"Points\"")) + 8;
  std::string bad = text;
  bad.insert(pointsOffset, "99");
  expectMessage(errorOf(bad), {"DataArray 'Points'", "offset '99", "is not within the"});
  // A count the data cannot hold fails before anything is allocated for it.
  expectMessage(errorOf(replaced(text, "NumberOfPoints=\"6\"", "NumberOfPoints=\"2000000000\"")),
                {"DataArray 'Points'", "header declares 144 bytes, the array needs 48000000000"});
  expectMessage(errorOf(replaced(text, "NumberOfPoints=\"6\"", "NumberOfPoints=\"999999999999\"")),
                {"bad.vtu:" + std::to_string(lineOf(text, "<Piece")) + ": Piece: NumberOfPoints '999999999999'"});
  // Cut anywhere inside the appended data.
  const size_t start = text.find('_', text.find("<AppendedData")) + 1;
  for (size_t cut = start; cut < text.rfind("</AppendedData>") - 1; cut += 5)
    expectMessage(errorOf(text.substr(0, cut)), {"bad.vtu"});
}

TEST(VtuBadInput, AsciiValues) {
  const int pointsLine = lineOf(kAscii, "NumberOfComponents=\"3\"");
  const std::string where = "bad.vtu:" + std::to_string(pointsLine) + ": DataArray (in Points): ";
  expectMessage(errorOf(replaced(kAscii, "0.1 0.2 0.3", "0.1 nan 0.3")), {where + "point 4: coordinate is not finite"});
  expectMessage(errorOf(replaced(kAscii, "0.1 0.2 0.3", "0.1 abc 0.3")),
                {where + "value 13: expected a number, found 'abc'"});
  expectMessage(errorOf(replaced(kAscii, "0.1 0.2 0.3", "0.1 0.2")), {where + "holds 14 values, expected 15"});
  expectMessage(errorOf(replaced(kAscii, "0.1 0.2 0.3", "0.1 0.2 0.3 4")), {where + "holds more than the 15 values"});
  expectMessage(errorOf(replaced(kAscii, "NumberOfPoints=\"5\"", "NumberOfPoints=\"100000000\"")),
                {where + "holds 15 values, expected 300000000"});
  expectMessage(errorOf(replaced(kAscii, "0 1 2 3 4 1 2", "0 1 2 3 4 1 x")),
                {"DataArray 'connectivity': value 6: expected an integer, found 'x'"});
  expectMessage(errorOf(replaced(kAscii, ">4 7<", ">4 3<")), {"DataArray 'offsets': cell 1: offset 3 is less than"});
  expectMessage(errorOf(replaced(kAscii, ">0 1 2 3<", ">0 1 2 4<")),
                {"DataArray 'connectivity': cell 2: point index 4"});
  expectMessage(errorOf(replaced(kAscii, "type=\"Int32\" Name=\"offsets\"", "type=\"Float32\" Name=\"offsets\"")),
                {"DataArray 'offsets': needs an integer type, not Float32"});
  test::expectEveryCutFails(kAscii, "cut.vtu", [](std::string_view text) { parseVtu(text, "cut.vtu"); });
}

TEST(VtuBadInput, UnsupportedFiles) {
  expectMessage(errorOf(replaced(kAscii, "UnstructuredGrid\" version", "PolyData\" version")),
                {"bad.vtu", "UnstructuredGrid"});
  expectMessage(errorOf(replaced(kAscii, "byte_order=\"LittleEndian\"", "compressor=\"vtkLZ4DataCompressor\"")),
                {"bad.vtu:2: VTKFile: unsupported compressor 'vtkLZ4DataCompressor'"});
  expectMessage(errorOf("<VTKFile><UnstructuredGrid>"), {"bad.vtu:", "not valid XML"});
  expectMessage(errorOf(replaced(kAscii, "format=\"ascii\">0 1 2 3 4", "format=\"hex\">0 1 2 3 4")),
                {"unknown format 'hex'"});
}

// ---- Writer ----------------------------------------------------------------------------------

// The doubles of the DataArray named `name`, read here without the reader under test.
std::vector<double> arrayDoubles(const std::string& text, const std::string& name, size_t count) {
  const size_t element = text.find("Name=\"" + name + "\"");
  EXPECT_NE(element, std::string::npos) << name;
  std::vector<double> values(count);
  const size_t offsetAttr = text.find("offset=\"", element);
  if (offsetAttr < text.find('>', element)) {  // appended raw: UInt64 byte count, then the values
    const size_t data = text.find('_', text.find("<AppendedData")) + 1 + std::stoul(text.substr(offsetAttr + 8));
    uint64_t bytes = 0;
    std::memcpy(&bytes, text.data() + data, sizeof bytes);
    EXPECT_EQ(bytes, count * sizeof(double));
    std::memcpy(values.data(), text.data() + data + sizeof bytes, count * sizeof(double));
    return values;
  }
  const char* p = text.data() + text.find('>', element) + 1;
  for (double& v : values) {
    while (std::isspace(static_cast<unsigned char>(*p))) ++p;
    p = std::from_chars(p, text.data() + text.size(), v).ptr;
  }
  return values;
}

TEST(VtuWrite, RoundTripIsBitExact) {
  const TetMesh mesh = test::jitteredBox(11);
  std::mt19937 random(5);
  std::normal_distribution<double> normal;
  PointField displacement{"displacement", {}}, velocity{"velocity", {}};
  for (int v = 0; v < mesh.vertexCount(); ++v) {
    displacement.values.emplace_back(normal(random), normal(random) * 1e-12, normal(random) * 1e12);
    velocity.values.emplace_back(v, -v, 0.5 * v);
  }
  const std::string byteOrder = hostIsLittleEndian() ? "LittleEndian" : "BigEndian";
  for (VtuEncoding encoding : {VtuEncoding::Ascii, VtuEncoding::AppendedRaw}) {
    SCOPED_TRACE(encoding == VtuEncoding::Ascii ? "ascii" : "appended raw");
    const std::string text = formatVtu(mesh, {displacement, velocity}, encoding);
    EXPECT_NE(text.find("byte_order=\"" + byteOrder + "\" header_type=\"UInt64\""), std::string::npos);
    const RawMesh raw = parseVtu(text, "round.vtu");
    test::expectSameMesh(mesh, raw.mesh);
    EXPECT_TRUE(raw.report.warnings.empty());
    for (const PointField* field : {&displacement, &velocity}) {
      const std::vector<double> values = arrayDoubles(text, field->name, 3 * field->values.size());
      for (size_t v = 0; v < field->values.size(); ++v)
        EXPECT_EQ(std::memcmp(&values[3 * v], field->values[v].data(), 3 * sizeof(double)), 0)
            << field->name << " " << v;
    }
    TetMesh noRegions = mesh;
    noRegions.tetRegion.clear();
    const std::string plain = formatVtu(noRegions, {}, encoding);
    EXPECT_EQ(plain.find("<CellData"), std::string::npos);
    EXPECT_EQ(parseVtu(plain, "plain.vtu").mesh.tetRegion, std::vector<int>(mesh.tetCount(), 0));
  }
  EXPECT_THROW(formatVtu(mesh, {{"short", {Eigen::Vector3d::Zero()}}}), MeshError);
}

} // namespace
} // namespace quiver
