// VTK legacy .vtk files, DATASET UNSTRUCTURED_GRID, ASCII or BINARY (big-endian): reading (tets
// only, classic and VTK 5.1 cell layouts, a region cell array) and writing (ASCII).
#include <algorithm>
#include <cctype>
#include <climits>
#include <cmath>
#include <type_traits>
#include <utility>

#include "formats/mesh/read_mesh.h"
#include "formats/mesh/text_cursor.h"
#include "formats/mesh/vtk_common.h"
#include "formats/mesh/write_mesh.h"

namespace quiver {

namespace {

using vtk::Scalar;

std::string upper(std::string_view s) {
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return out;
}

// A legacy data type: a number type, or one of the two kinds that are only ever skipped.
struct DataType {
  enum Kind { Number, Bit, String } kind = Number;
  Scalar scalar = Scalar::Float64;
};

class LegacyReader {
public:
  LegacyReader(std::string_view bytes, const std::string& file) : text_(bytes, file), bytes_(bytes) {
    out_.source.file = file;
  }
  RawMesh read();

private:
  enum class Section { None, PointData, CellData };

  void readPoints();
  void readCells();
  void readClassicCells(int64_t cellCount, int64_t listSize);
  void readOffsetsAndConnectivity(int64_t offsetCount, int64_t connectivitySize);
  void readCellTypes();
  void readAttribute(const std::string& keyword);
  void readField();
  void readArray(const std::string& name, int64_t position, int64_t components, int64_t tuples, DataType type);
  void skipMetadata();
  DataType dataType();

  // Reads n values of `type` as T (int64_t or double), calling sink(value, position): the line
  // (ASCII) or byte offset (BINARY) where the value is written.
  template <class T, class Sink>
  void values(int64_t n, Scalar type, const char* what, Sink&& sink);
  void skipValues(int64_t n, DataType type, const std::string& what);
  size_t beginBinary();                                 // start of the data after the header line
  void checkFits(int64_t n, int64_t bytesEach, const std::string& what);
  int64_t here() const { return binary_ ? static_cast<int64_t>(text_.position()) : text_.line(); }
  std::string at(int64_t position) const {  // "file:line" or "file: byte N"
    return text_.file() + (binary_ ? ": byte " : ":") + std::to_string(position);
  }
  [[noreturn]] void failAt(int64_t position, const std::string& message) const {
    throw MeshError(at(position) + ": " + message);
  }

  TextCursor text_;
  std::string_view bytes_;
  bool binary_ = false;
  RawMesh out_;
  bool havePoints_ = false, haveCells_ = false;
  vtk::CellList cells_;
  std::vector<int64_t> types_;
  std::vector<int64_t> regions_;
  std::string regionName_;
  Section section_ = Section::None;
  int64_t sectionCount_ = 0;
};

RawMesh LegacyReader::read() {
  if (text_.restOfLine().rfind("# vtk DataFile Version", 0) != 0)
    text_.fail("not a VTK legacy file: the first line must start with '# vtk DataFile Version'");
  text_.restOfLine();  // title
  const std::string mode = upper(text_.restOfLine());
  if (mode != "ASCII" && mode != "BINARY") text_.fail("expected ASCII or BINARY, found '" + mode + "'");
  binary_ = mode == "BINARY";
  if (upper(text_.token("DATASET")) != "DATASET") text_.fail("expected DATASET");
  const std::string dataset = upper(text_.token("dataset type"));
  if (dataset != "UNSTRUCTURED_GRID") text_.fail("only DATASET UNSTRUCTURED_GRID is supported, found " + dataset);

  out_.source.positionKind = binary_ ? SourcePositionKind::ByteOffset : SourcePositionKind::Line;
  while (!text_.atEnd()) {
    const std::string keyword = upper(text_.token("keyword"));
    if (keyword == "POINTS") readPoints();
    else if (keyword == "CELLS") readCells();
    else if (keyword == "CELL_TYPES") readCellTypes();
    else if (keyword == "FIELD") readField();
    else if (keyword == "METADATA") skipMetadata();
    else if (keyword == "POINT_DATA" || keyword == "CELL_DATA") {
      section_ = keyword == "POINT_DATA" ? Section::PointData : Section::CellData;
      sectionCount_ = text_.count("attribute count", 0);
    } else readAttribute(keyword);
  }

  const std::string& file = text_.file();
  if (!havePoints_) throw MeshError(file + ": no POINTS section");
  if (!haveCells_) throw MeshError(file + ": no CELLS section");
  const size_t cellCount = cells_.positions.size();
  if (types_.size() != cellCount)
    throw MeshError(file + ": CELL_TYPES lists " + std::to_string(types_.size()) + " cells, CELLS has " +
                    std::to_string(cellCount));
  if (!regions_.empty() && regions_.size() != cellCount)
    throw MeshError(file + ": cell array '" + regionName_ + "' has " + std::to_string(regions_.size()) +
                    " values for " + std::to_string(cellCount) + " cells");
  cells_.types = std::move(types_);
  vtk::TetCollector collector(out_);
  collector.add(cells_, regions_, 0, out_.mesh.vertexCount(), 0,
                [&](size_t c) { return at(cells_.positions[c]) + ": cell " + std::to_string(c); });
  collector.finish();
  return std::move(out_);
}

DataType LegacyReader::dataType() {
  std::string name(text_.token("data type"));
  for (char& c : name) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  // VTK's names; the sized vtktype* names other than the 64-bit ones are meshio's (for OFFSETS/CONNECTIVITY).
  static const std::pair<const char*, Scalar> kNames[] = {
      {"char", Scalar::Int8},           {"signed_char", Scalar::Int8},      {"unsigned_char", Scalar::UInt8},
      {"short", Scalar::Int16},         {"unsigned_short", Scalar::UInt16}, {"int", Scalar::Int32},
      {"unsigned_int", Scalar::UInt32}, {"long", Scalar::Int64},            {"unsigned_long", Scalar::UInt64},
      {"float", Scalar::Float32},       {"double", Scalar::Float64},
      {"vtkidtype", Scalar::Int32},  // VTK writes vtkIdType arrays as int
      {"vtktypeint8", Scalar::Int8},    {"vtktypeuint8", Scalar::UInt8},    {"vtktypeint16", Scalar::Int16},
      {"vtktypeuint16", Scalar::UInt16}, {"vtktypeint32", Scalar::Int32},   {"vtktypeuint32", Scalar::UInt32},
      {"vtktypeint64", Scalar::Int64},  {"vtktypeuint64", Scalar::UInt64},
  };
  for (const auto& [n, scalar] : kNames)
    if (name == n) return {DataType::Number, scalar};
  if (name == "bit") return {DataType::Bit, Scalar::UInt8};
  if (name == "string" || name == "utf8_string") return {DataType::String, Scalar::UInt8};
  text_.fail("unknown data type '" + name + "'");
}

void LegacyReader::readPoints() {
  if (havePoints_) text_.fail("second POINTS section");
  const int64_t n = text_.count("point count", 6);  // "0 0 0\n" at least, in ASCII or BINARY
  if (n > INT_MAX) text_.fail("point count " + std::to_string(n) + " is too large");
  const DataType type = dataType();
  if (type.kind != DataType::Number) text_.fail("POINTS need a number type");
  std::vector<Eigen::Vector3d>& vertices = out_.mesh.vertices;
  vertices.reserve(static_cast<size_t>(n));
  int64_t k = 0;
  values<double>(3 * n, type.scalar, "point coordinate", [&](double v, int64_t position) {
    if (!std::isfinite(v)) failAt(position, "point " + std::to_string(k / 3) + ": coordinate is not finite");
    if (k % 3 == 0) vertices.emplace_back();
    vertices.back()[k % 3] = v;
    ++k;
  });
  for (int64_t i = 0; i < n; ++i) out_.source.vertexFileId.push_back(i);
  havePoints_ = true;
}

void LegacyReader::readCells() {
  if (haveCells_) text_.fail("second CELLS section");
  const int64_t first = text_.count("cell count", 1), second = text_.count("cell list size", 1);
  if (upper(text_.peekToken()) == "OFFSETS") readOffsetsAndConnectivity(first, second);
  else readClassicCells(first, second);
  haveCells_ = true;
}

// "CELLS n size" then per cell "k i0 .. ik-1" (int32 in BINARY).
void LegacyReader::readClassicCells(int64_t cellCount, int64_t listSize) {
  cells_.offsets.push_back(0);
  int64_t pending = 0;  // points still to read for the current cell
  values<int64_t>(listSize, Scalar::Int32, "cell list", [&](int64_t v, int64_t position) {
    if (pending > 0) {
      cells_.connectivity.push_back(v);
      if (--pending == 0) cells_.offsets.push_back(static_cast<int64_t>(cells_.connectivity.size()));
      return;
    }
    const int64_t cell = static_cast<int64_t>(cells_.positions.size());
    if (cell == cellCount)
      failAt(position, "the cell list holds more than the " + std::to_string(cellCount) + " cells CELLS declares");
    if (v < 0 || v > listSize)
      failAt(position, "cell " + std::to_string(cell) + ": point count " + std::to_string(v) + " is invalid");
    cells_.positions.push_back(position);
    pending = v;
    if (v == 0) cells_.offsets.push_back(static_cast<int64_t>(cells_.connectivity.size()));
  });
  if (pending > 0) failAt(here(), "the cell list ends inside cell " + std::to_string(cells_.positions.size() - 1));
  if (static_cast<int64_t>(cells_.positions.size()) != cellCount)
    failAt(here(), "the cell list holds " + std::to_string(cells_.positions.size()) + " cells, CELLS declares " +
                       std::to_string(cellCount));
}

// VTK 5.1: "CELLS nOffsets nConnectivity", "OFFSETS type" + nOffsets values from 0, "CONNECTIVITY type" + values.
void LegacyReader::readOffsetsAndConnectivity(int64_t offsetCount, int64_t connectivitySize) {
  text_.token("OFFSETS");
  std::vector<int64_t> offsetPositions;
  DataType type = dataType();
  if (type.kind != DataType::Number) text_.fail("OFFSETS need an integer type");
  values<int64_t>(offsetCount, type.scalar, "cell offset", [&](int64_t v, int64_t position) {
    const int64_t previous = cells_.offsets.empty() ? 0 : cells_.offsets.back();
    if (v < previous || v > connectivitySize || (cells_.offsets.empty() && v != 0))
      failAt(position, "cell offset " + std::to_string(v) + " is out of order or beyond the " +
                           std::to_string(connectivitySize) + " connectivity entries");
    cells_.offsets.push_back(v);
    offsetPositions.push_back(position);
  });
  if (cells_.offsets.empty()) cells_.offsets.push_back(0);
  if (cells_.offsets.back() != connectivitySize)
    failAt(here(), "the last cell offset is " + std::to_string(cells_.offsets.back()) + ", CELLS declares " +
                       std::to_string(connectivitySize) + " connectivity entries");
  if (upper(text_.token("CONNECTIVITY")) != "CONNECTIVITY") text_.fail("expected CONNECTIVITY");
  type = dataType();
  if (type.kind != DataType::Number) text_.fail("CONNECTIVITY needs an integer type");
  std::vector<int64_t> connectivityPositions;
  values<int64_t>(connectivitySize, type.scalar, "connectivity", [&](int64_t v, int64_t position) {
    cells_.connectivity.push_back(v);
    connectivityPositions.push_back(position);
  });
  for (size_t c = 0; c + 1 < cells_.offsets.size(); ++c) {  // a cell is where its first point is written
    const int64_t begin = cells_.offsets[c];
    cells_.positions.push_back(begin < cells_.offsets[c + 1] ? connectivityPositions[static_cast<size_t>(begin)]
                                                             : offsetPositions[c]);
  }
}

void LegacyReader::readCellTypes() {
  if (!types_.empty()) text_.fail("second CELL_TYPES section");
  const int64_t n = text_.count("cell type count", 2);
  values<int64_t>(n, Scalar::Int32, "cell type", [&](int64_t v, int64_t) { types_.push_back(v); });
}

// SCALARS, VECTORS, ... inside POINT_DATA or CELL_DATA.
void LegacyReader::readAttribute(const std::string& keyword) {
  static const char* const kAttributes[] = {"SCALARS", "COLOR_SCALARS", "LOOKUP_TABLE", "VECTORS", "NORMALS",
                                            "TEXTURE_COORDINATES", "TENSORS", "TENSORS6", "GLOBAL_IDS",
                                            "PEDIGREE_IDS", "EDGE_FLAGS"};
  if (std::find(std::begin(kAttributes), std::end(kAttributes), keyword) == std::end(kAttributes))
    text_.fail("unknown keyword '" + keyword + "'");
  if (section_ == Section::None) text_.fail(keyword + " outside POINT_DATA and CELL_DATA");
  const std::string name(text_.token("array name"));
  const int64_t position = here();
  // Colours are floats in ASCII and bytes in BINARY.
  const DataType colour{DataType::Number, binary_ ? Scalar::UInt8 : Scalar::Float32};
  if (keyword == "SCALARS") {
    const DataType type = dataType();
    const int64_t components = text_.atLineEnd() ? 1 : text_.integerInRange("component count", 1, 1 << 16);
    if (upper(text_.peekToken()) == "LOOKUP_TABLE") {
      text_.token("LOOKUP_TABLE");
      text_.token("lookup table name");
    }
    readArray(name, position, components, sectionCount_, type);
  } else if (keyword == "COLOR_SCALARS") {
    readArray(name, position, text_.integerInRange("component count", 1, 1 << 16), sectionCount_, colour);
  } else if (keyword == "LOOKUP_TABLE") {
    readArray(name, position, 4, text_.count("lookup table size", 4), colour);
  } else if (keyword == "TEXTURE_COORDINATES") {
    const int64_t dimension = text_.integerInRange("texture dimension", 1, 3);
    readArray(name, position, dimension, sectionCount_, dataType());
  } else {
    const int64_t components = keyword == "VECTORS" || keyword == "NORMALS" ? 3
                               : keyword == "TENSORS"                       ? 9
                               : keyword == "TENSORS6"                      ? 6
                                                                            : 1;
    readArray(name, position, components, sectionCount_, dataType());
  }
}

// "FIELD name k" then k times "arrayName components tuples type" and the values.
void LegacyReader::readField() {
  text_.token("field name");
  const int64_t arrays = text_.count("field array count", 8);
  for (int64_t i = 0; i < arrays; ++i) {
    const std::string name(text_.token("field array name"));
    if (name == "NULL_ARRAY") continue;  // what VTK writes for an array it cannot write
    const int64_t position = here();
    const int64_t components = text_.integerInRange("component count", 0, 1 << 16);
    const int64_t tuples = text_.count("tuple count", 0);
    readArray(name, position, components, tuples, dataType());
  }
}

void LegacyReader::readArray(const std::string& name, int64_t position, int64_t components, int64_t tuples,
                             DataType type) {
  if (tuples > INT64_MAX / (1 << 16)) text_.fail("array '" + name + "' is too large");
  if (section_ == Section::CellData && components == 1 && regions_.empty() && vtk::isRegionArrayName(name)) {
    if (type.kind == DataType::Number && !vtk::isFloating(type.scalar)) {
      regionName_ = name;
      values<int64_t>(tuples, type.scalar, "region", [&](int64_t v, int64_t) { regions_.push_back(v); });
      return;
    }
    out_.report.warnings.push_back(vtk::nonIntegerRegionWarning(at(position), name));
  }
  skipValues(components * tuples, type, name);
}

// Array metadata: lines up to the next blank line.
void LegacyReader::skipMetadata() {
  text_.restOfLine();
  while (text_.position() < bytes_.size() && !text_.restOfLine().empty()) {
  }
}

size_t LegacyReader::beginBinary() {
  const std::string_view rest = text_.restOfLine();
  if (!rest.empty()) text_.fail("unexpected text before binary data: '" + std::string(rest.substr(0, 40)) + "'");
  return text_.position();
}

void LegacyReader::checkFits(int64_t n, int64_t bytesEach, const std::string& what) {
  const int64_t remaining = static_cast<int64_t>(bytes_.size() - text_.position());
  if (n < 0 || n > remaining / bytesEach)
    failAt(here(), what + ": " + std::to_string(n) + " values cannot fit in the " + std::to_string(remaining) +
                       " bytes left in the file (truncated?)");
}

template <class T, class Sink>
void LegacyReader::values(int64_t n, Scalar type, const char* what, Sink&& sink) {
  if (std::is_same_v<T, int64_t> && vtk::isFloating(type)) text_.fail(std::string(what) + " needs an integer type");
  if (!binary_) {
    checkFits(n, 2, what);  // a digit and a separator each
    for (int64_t i = 0; i < n; ++i) {
      T v;
      if constexpr (std::is_same_v<T, double>) v = text_.real(what);
      else v = text_.integer(what);
      sink(v, static_cast<int64_t>(text_.line()));
    }
    return;
  }
  checkFits(n, static_cast<int64_t>(vtk::scalarBytes(type)), what);
  ByteCursor in(bytes_, beginBinary(), text_.file(), hostIsLittleEndian());
  for (int64_t i = 0; i < n; ++i) {
    const int64_t position = static_cast<int64_t>(in.position());
    sink(vtk::readScalar<T>(in, type, what), position);
  }
  text_.seek(in.position());
}

void LegacyReader::skipValues(int64_t n, DataType type, const std::string& what) {
  if (!binary_) {
    if (type.kind == DataType::String) {  // one (encoded) string per line
      text_.restOfLine();
      checkFits(n, 1, what);
      for (int64_t i = 0; i < n; ++i)
        if (text_.position() >= bytes_.size()) failAt(here(), "unexpected end of file in string array '" + what + "'");
        else text_.restOfLine();
      return;
    }
    checkFits(n, 2, what);
    for (int64_t i = 0; i < n; ++i) text_.token(what.c_str());
    return;
  }
  if (type.kind == DataType::String) text_.fail("string arrays in BINARY files are not supported ('" + what + "')");
  const int64_t bytes =
      type.kind == DataType::Bit ? (n + 7) / 8 : n * static_cast<int64_t>(vtk::scalarBytes(type.scalar));
  checkFits(bytes, 1, what);
  text_.seek(beginBinary() + static_cast<size_t>(bytes));
}

} // namespace

RawMesh parseVtkLegacy(std::string_view bytes, const std::string& file) { return LegacyReader(bytes, file).read(); }

std::string formatVtkLegacy(const TetMesh& mesh, const std::vector<PointField>& fields) {
  vtk::checkWritable(mesh, fields, "VTK legacy");
  for (const PointField& f : fields)
    if (std::any_of(f.name.begin(), f.name.end(), [](char c) { return std::isspace(static_cast<unsigned char>(c)); }))
      throw MeshError("VTK legacy: point field name '" + f.name + "' contains whitespace");
  const int64_t n = mesh.vertexCount(), m = mesh.tetCount();
  std::string s = "# vtk DataFile Version 3.0\nQuiver tetrahedral mesh\nASCII\nDATASET UNSTRUCTURED_GRID\n";
  auto appendVectors = [&s](const std::vector<Eigen::Vector3d>& vectors) {
    for (const Eigen::Vector3d& v : vectors) {
      for (int k = 0; k < 3; ++k) {
        vtk::appendNumber(s, v[k]);
        s += k < 2 ? ' ' : '\n';
      }
    }
  };
  s += "POINTS " + std::to_string(n) + " double\n";
  appendVectors(mesh.vertices);
  s += "CELLS " + std::to_string(m) + " " + std::to_string(5 * m) + "\n";
  for (const Tet& t : mesh.tets) {
    s += '4';
    for (int v : t) {
      s += ' ';
      vtk::appendNumber(s, static_cast<int64_t>(v));
    }
    s += '\n';
  }
  s += "CELL_TYPES " + std::to_string(m) + "\n";
  for (int64_t t = 0; t < m; ++t) s += "10\n";
  if (!mesh.tetRegion.empty()) {
    s += "CELL_DATA " + std::to_string(m) + "\nSCALARS region int 1\nLOOKUP_TABLE default\n";
    for (int r : mesh.tetRegion) {
      vtk::appendNumber(s, static_cast<int64_t>(r));
      s += '\n';
    }
  }
  if (!fields.empty()) {
    s += "POINT_DATA " + std::to_string(n) + "\n";
    for (const PointField& f : fields) {
      s += "VECTORS " + f.name + " double\n";
      appendVectors(f.values);
    }
  }
  return s;
}

} // namespace quiver
