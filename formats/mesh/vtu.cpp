// VTK XML .vtu files (UnstructuredGrid). Reading takes every DataArray encoding VTK writes:
// ascii, inline base64 "binary" and <AppendedData> (raw or base64), each optionally
// zlib-compressed, in either byte order, with UInt32 or UInt64 headers. Writing makes ascii or
// appended raw files.
#include <tinyxml2.h>
#include <zlib.h>

#include <algorithm>
#include <climits>
#include <type_traits>

#include "formats/mesh/read_mesh.h"
#include "formats/mesh/text_cursor.h"
#include "formats/mesh/vtk_common.h"
#include "formats/mesh/write_mesh.h"
#include "formats/xml_text.h"

namespace quiver {

namespace {

using tinyxml2::XMLElement;
using vtk::Scalar;

// What <VTKFile> says about every binary DataArray, and where <AppendedData> is.
struct VtuFile {
  std::string file;
  bool swap = false;          // byte_order differs from this machine's
  size_t headerBytes = 4;     // header_type UInt32 (the default) or UInt64
  bool compressed = false;    // compressor="vtkZLibDataCompressor"
  std::string_view appended;  // the bytes after <AppendedData ...> and its '_'
  size_t appendedStart = 0;   // file offset of appended[0]
  bool appendedBase64 = false;
};

bool isBlank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; }

// "file:line: DataArray 'Name'" (or "DataArray (in Points)" when it has no name).
std::string describe(const VtuFile& f, const XMLElement* e) {
  std::string s = f.file + ":" + std::to_string(e->GetLineNum()) + ": " + e->Name();
  const XMLElement* parent = e->Parent() ? e->Parent()->ToElement() : nullptr;
  if (const char* name = e->Attribute("Name")) s += " '" + std::string(name) + "'";
  else if (std::string_view(e->Name()) == "DataArray" && parent) s += std::string(" (in ") + parent->Name() + ")";
  return s;
}

[[noreturn]] void fail(const VtuFile& f, const XMLElement* e, const std::string& message) {
  throw MeshError(describe(f, e) + ": " + message);
}

// The binary data of one DataArray, decoded on demand: raw bytes from <AppendedData> or base64
// text. Base64 made of several padded pieces (VTK encodes a compressed array's header and its
// blocks separately) decodes to their concatenation.
class Payload {
public:
  // `fileOffset`: the file offset of data[0], or npos for a DataArray's own text.
  Payload(std::string_view data, bool base64, std::string where, size_t fileOffset)
      : data_(data), base64_(base64), where_(std::move(where)), fileOffset_(fileOffset) {}

  // Upper bound on the number of bytes the data can decode to.
  uint64_t capacity() const { return base64_ ? data_.size() / 4 * 3 + 3 : data_.size(); }

  // The first n decoded bytes, or MeshError when the data holds fewer.
  std::string_view prefix(uint64_t n) {
    if (n > capacity()) fail("needs " + std::to_string(n) + " bytes, more than its data holds (truncated?)");
    if (!base64_) return data_.substr(0, n);
    while (decoded_.size() < n) decodeGroup(n);
    return std::string_view(decoded_).substr(0, n);
  }

  // Header word `index` (UInt32 or UInt64).
  uint64_t word(size_t index, const VtuFile& f) {
    ByteCursor in(prefix((index + 1) * f.headerBytes), index * f.headerBytes, where_, f.swap);
    return f.headerBytes == 4 ? in.read<uint32_t>("header") : in.read<uint64_t>("header");
  }

  // "byte N" (file offset) for raw data, "decoded byte N" for base64.
  std::string byteAt(uint64_t offset) const {
    return base64_ ? "decoded byte " + std::to_string(offset) : "byte " + std::to_string(fileOffset_ + offset);
  }
  [[noreturn]] void fail(const std::string& message) const { throw MeshError(where_ + ": " + message); }

private:
  void decodeGroup(uint64_t needed) {
    uint32_t bits = 0;
    int chars = 0, padding = 0;
    while (chars < 4) {
      if (used_ == data_.size()) {
        fail(chars == 0 ? "base64 data ends after " + std::to_string(decoded_.size()) + " bytes, " +
                              std::to_string(needed) + " needed (truncated?)"
                        : "base64 data ends inside a group of four characters");
      }
      const size_t at = used_++;
      const char c = data_[at];
      if (isBlank(c)) continue;
      int v = -1;
      if (c >= 'A' && c <= 'Z') v = c - 'A';
      else if (c >= 'a' && c <= 'z') v = c - 'a' + 26;
      else if (c >= '0' && c <= '9') v = c - '0' + 52;
      else if (c == '+') v = 62;
      else if (c == '/') v = 63;
      else if (c == '=' && chars >= 2) v = 0, ++padding;
      if (v < 0 || (padding > 0 && c != '='))
        fail("invalid base64 character '" + std::string(1, c) + "' at " +
             (fileOffset_ == std::string_view::npos ? "character " + std::to_string(at) + " of its text"
                                                    : "byte " + std::to_string(fileOffset_ + at)));
      bits = bits << 6 | static_cast<uint32_t>(v);
      ++chars;
    }
    for (int k = 0; k < 3 - padding; ++k) decoded_ += static_cast<char>(bits >> (16 - 8 * k) & 0xff);
  }

  std::string_view data_;
  bool base64_;
  std::string where_;
  size_t fileOffset_;
  std::string decoded_;
  size_t used_ = 0;  // characters of data_ decoded so far
};

// The uncompressed bytes of an array (`expectedBytes` of them), following its header. Compressed
// data is "[blocks][block size][last block size][compressed size]..." then the zlib blocks.
std::string_view arrayBytes(const VtuFile& f, Payload& p, uint64_t expectedBytes, std::string& inflated) {
  const size_t w = f.headerBytes;
  if (!f.compressed) {
    const uint64_t size = p.word(0, f);
    if (size != expectedBytes)
      p.fail("header declares " + std::to_string(size) + " bytes, the array needs " + std::to_string(expectedBytes));
    return p.prefix(w + size).substr(w);
  }
  const uint64_t blocks = p.word(0, f);
  if (blocks > p.capacity() / w)
    p.fail("compression header declares " + std::to_string(blocks) + " blocks, more than the data holds");
  const uint64_t blockSize = p.word(1, f), lastSize = p.word(2, f);
  const uint64_t headerSize = (3 + blocks) * w;
  p.prefix(headerSize);
  if (blocks > 0 && (blockSize == 0 || lastSize > blockSize))
    p.fail("invalid compression header: block size " + std::to_string(blockSize) + ", last block size " +
           std::to_string(lastSize));
  const auto uncompressedSize = [&](uint64_t b) { return b + 1 < blocks || lastSize == 0 ? blockSize : lastSize; };
  // The uncompressed total, unless it is larger than the array (it may not even fit in 64 bits).
  const bool tooLarge =
      blocks > 0 && (blocks - 1 > expectedBytes / blockSize || uncompressedSize(blocks - 1) > expectedBytes);
  const uint64_t total = blocks == 0 || tooLarge ? 0 : (blocks - 1) * blockSize + uncompressedSize(blocks - 1);
  if (tooLarge || total != expectedBytes)
    p.fail("compression header declares " + std::to_string(blocks) + " blocks of " + std::to_string(blockSize) +
           " bytes (last " + std::to_string(lastSize) + "), " + (tooLarge ? "more than" : std::to_string(total)) +
           " bytes in all; the array needs " + std::to_string(expectedBytes));
  std::vector<uint64_t> sizes(blocks);
  uint64_t compressedTotal = 0;
  for (uint64_t b = 0; b < blocks; ++b) {
    sizes[b] = p.word(3 + b, f);
    if (sizes[b] > p.capacity() - headerSize - compressedTotal)
      p.fail("compressed block " + std::to_string(b) + " of " + std::to_string(sizes[b]) +
             " bytes runs past the end of the data (truncated?)");
    if (uncompressedSize(b) > sizes[b] * 1032 + 64)  // zlib's best ratio is about 1032:1
      p.fail("compressed block " + std::to_string(b) + " of " + std::to_string(sizes[b]) + " bytes cannot inflate to " +
             std::to_string(uncompressedSize(b)) + " bytes");
    compressedTotal += sizes[b];
  }
  const std::string_view data = p.prefix(headerSize + compressedTotal).substr(headerSize);
  inflated.resize(expectedBytes);
  uint64_t in = 0, out = 0;
  for (uint64_t b = 0; b < blocks; ++b) {
    uLongf length = uncompressedSize(b);
    const int rc = uncompress(reinterpret_cast<Bytef*>(inflated.data() + out), &length,
                              reinterpret_cast<const Bytef*>(data.data() + in), sizes[b]);
    if (rc != Z_OK || length != uncompressedSize(b))
      p.fail(p.byteAt(headerSize + in) + ": compressed block " + std::to_string(b) + " does not inflate to the " +
             std::to_string(uncompressedSize(b)) + " bytes its header declares (" +
             (rc == Z_OK ? "it holds " + std::to_string(length) : std::string(zError(rc))) + ")");
    in += sizes[b];
    out += length;
  }
  return inflated;
}

template <class T>
std::vector<T> asciiValues(const char* text, int64_t expected, const VtuFile& f, const XMLElement* array) {
  const std::string_view s = text ? text : "";
  std::vector<T> out;
  out.reserve(std::min<size_t>(static_cast<size_t>(expected), s.size() / 2 + 1));
  for (size_t i = 0;;) {
    while (i < s.size() && isBlank(s[i])) ++i;
    if (i == s.size()) break;
    const size_t start = i;
    while (i < s.size() && !isBlank(s[i])) ++i;
    const std::string_view token = s.substr(start, i - start);
    if (static_cast<int64_t>(out.size()) == expected)
      fail(f, array, "holds more than the " + std::to_string(expected) + " values expected");
    T v;
    bool ok;
    if constexpr (std::is_same_v<T, double>) ok = parseReal(token, v);
    else ok = parseInteger(token, v);
    if (!ok)
      fail(f, array, "value " + std::to_string(out.size()) + ": expected " +
                         (std::is_same_v<T, double> ? "a number" : "an integer") + ", found '" +
                         std::string(token.substr(0, 40)) + "'");
    out.push_back(v);
  }
  if (static_cast<int64_t>(out.size()) != expected)
    fail(f, array,
         "holds " + std::to_string(out.size()) + " values, expected " + std::to_string(expected) + " (truncated?)");
  return out;
}

// The `expected` values (components x tuples) of a DataArray, as T (int64_t or double).
template <class T>
std::vector<T> readDataArray(const VtuFile& f, const XMLElement* array, int64_t expected) {
  Scalar type;
  const char* typeName = array->Attribute("type");
  if (!typeName || !vtk::parseXmlScalar(typeName, type))
    fail(f, array, std::string("unsupported type '") + (typeName ? typeName : "") + "'");
  if (std::is_same_v<T, int64_t> && vtk::isFloating(type))
    fail(f, array, std::string("needs an integer type, not ") + typeName);
  if (expected > INT64_MAX / 8) fail(f, array, "declares " + std::to_string(expected) + " values, too many");
  const std::string format = array->Attribute("format") ? array->Attribute("format") : "";
  if (format == "ascii") return asciiValues<T>(array->GetText(), expected, f, array);

  std::string_view data;
  bool base64 = true;
  size_t fileOffset = std::string_view::npos;
  if (format == "binary") {
    data = array->GetText() ? array->GetText() : "";
  } else if (format == "appended") {
    int64_t offset;
    const char* offsetText = array->Attribute("offset");
    if (!offsetText || !parseInteger(offsetText, offset) || offset < 0 ||
        static_cast<uint64_t>(offset) > f.appended.size())
      fail(f, array, std::string("offset '") + (offsetText ? offsetText : "") + "' is not within the " +
                         std::to_string(f.appended.size()) + " bytes of <AppendedData>");
    data = f.appended.substr(static_cast<size_t>(offset));
    base64 = f.appendedBase64;
    fileOffset = f.appendedStart + static_cast<size_t>(offset);
  } else {
    fail(f, array, "unknown format '" + format + "'");
  }
  Payload payload(data, base64, describe(f, array), fileOffset);
  std::string inflated;
  const std::string_view bytes =
      arrayBytes(f, payload, static_cast<uint64_t>(expected) * vtk::scalarBytes(type), inflated);
  ByteCursor in(bytes, 0, describe(f, array), f.swap);
  std::vector<T> out;
  out.reserve(static_cast<size_t>(expected));
  for (int64_t i = 0; i < expected; ++i) out.push_back(vtk::readScalar<T>(in, type, "value"));
  return out;
}

int64_t intAttribute(const VtuFile& f, const XMLElement* e, const char* name, int64_t fallback, int64_t hi) {
  const char* text = e->Attribute(name);
  int64_t v = fallback;
  if (text && (!parseInteger(text, v) || v < 0 || v > hi))
    fail(f, e, std::string(name) + " '" + text + "' is not an integer in [0, " + std::to_string(hi) + "]");
  return v;
}

const XMLElement* child(const VtuFile& f, const XMLElement* parent, const char* name) {
  const XMLElement* e = parent->FirstChildElement(name);
  if (!e) fail(f, parent, std::string("has no <") + name + ">");
  return e;
}

const XMLElement* namedArray(const VtuFile& f, const XMLElement* cells, std::string_view name) {
  for (const XMLElement* a = cells->FirstChildElement("DataArray"); a; a = a->NextSiblingElement("DataArray"))
    if (a->Attribute("Name") && a->Attribute("Name") == name) return a;
  fail(f, cells, "has no DataArray '" + std::string(name) + "'");
}

// Appends one <Piece>: its point indices are local to it and shifted past the earlier pieces'
// points; `cellBase` counts the cells of earlier pieces.
void readPiece(const VtuFile& f, const XMLElement* piece, RawMesh& out, vtk::TetCollector& collector,
               int64_t& cellBase) {
  const int64_t pointBase = out.mesh.vertexCount();
  const int64_t points = intAttribute(f, piece, "NumberOfPoints", -1, INT_MAX - pointBase);
  const int64_t cells = intAttribute(f, piece, "NumberOfCells", -1, INT_MAX);
  if (points < 0 || cells < 0) fail(f, piece, "needs NumberOfPoints and NumberOfCells");

  const XMLElement* pointArray = child(f, child(f, piece, "Points"), "DataArray");
  if (intAttribute(f, pointArray, "NumberOfComponents", 1, INT_MAX) != 3)
    fail(f, pointArray, "needs NumberOfComponents=\"3\"");
  const std::vector<double> xyz = readDataArray<double>(f, pointArray, 3 * points);
  for (int64_t i = 0; i < points; ++i) {
    const Eigen::Vector3d x(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
    if (!x.allFinite()) fail(f, pointArray, "point " + std::to_string(i) + ": coordinate is not finite");
    out.mesh.vertices.push_back(x);
    out.source.vertexFileId.push_back(pointBase + i);
  }

  const XMLElement* cellsElement = child(f, piece, "Cells");
  const XMLElement* offsetArray = namedArray(f, cellsElement, "offsets");
  const XMLElement* connectivityArray = namedArray(f, cellsElement, "connectivity");
  vtk::CellList list;
  list.offsets = readDataArray<int64_t>(f, offsetArray, cells);
  list.offsets.insert(list.offsets.begin(), 0);  // VTK stores where each cell ends
  for (int64_t c = 0; c < cells; ++c)
    if (list.offsets[c + 1] < list.offsets[c])
      fail(f, offsetArray, "cell " + std::to_string(cellBase + c) + ": offset " + std::to_string(list.offsets[c + 1]) +
                               " is less than the previous offset " + std::to_string(list.offsets[c]));
  list.types = readDataArray<int64_t>(f, namedArray(f, cellsElement, "types"), cells);
  list.connectivity = readDataArray<int64_t>(f, connectivityArray, list.offsets.back());
  for (int64_t c = 0; c < cells; ++c) list.positions.push_back(cellBase + c);

  std::vector<int64_t> regions;
  const XMLElement* cellData = piece->FirstChildElement("CellData");
  for (const XMLElement* a = cellData ? cellData->FirstChildElement("DataArray") : nullptr; a;
       a = a->NextSiblingElement("DataArray")) {
    const char* name = a->Attribute("Name");
    if (!name || !vtk::isRegionArrayName(name) || intAttribute(f, a, "NumberOfComponents", 1, INT_MAX) != 1) continue;
    Scalar type;
    if (a->Attribute("type") && vtk::parseXmlScalar(a->Attribute("type"), type) && vtk::isFloating(type)) {
      out.report.warnings.push_back(vtk::nonIntegerRegionWarning(describe(f, a), name));
      continue;
    }
    regions = readDataArray<int64_t>(f, a, cells);
    break;
  }
  collector.add(list, regions, pointBase, points, cellBase, [&](size_t c) {
    return describe(f, connectivityArray) + ": cell " + std::to_string(cellBase + static_cast<int64_t>(c));
  });
  cellBase += cells;
}

// Raw appended data is not XML: finds <AppendedData encoding="..."> and the bytes after its '_'.
void locateAppendedData(std::string_view bytes, size_t tagStart, VtuFile& f) {
  const size_t tagEnd = bytes.find('>', tagStart);
  if (tagEnd == std::string_view::npos)
    throw MeshError(f.file + ": byte " + std::to_string(tagStart) + ": unterminated <AppendedData> tag");
  std::string tag(bytes.substr(tagStart, tagEnd - tagStart));
  if (tag.back() == '/') return;  // <AppendedData/>: nothing appended
  tag += "/>";
  tinyxml2::XMLDocument doc;
  const char* encoding = doc.Parse(tag.data(), tag.size()) == tinyxml2::XML_SUCCESS
                             ? doc.RootElement()->Attribute("encoding") : nullptr;
  const std::string enc = encoding ? encoding : "";
  if (enc != "raw" && enc != "base64")
    throw MeshError(f.file + ": byte " + std::to_string(tagStart) +
                    ": <AppendedData> needs encoding=\"raw\" or \"base64\"");
  size_t start = tagEnd + 1;
  while (start < bytes.size() && isBlank(bytes[start])) ++start;
  if (start == bytes.size() || bytes[start] != '_')
    throw MeshError(f.file + ": byte " + std::to_string(start) + ": the data in <AppendedData> must start with '_'");
  ++start;
  size_t end = bytes.rfind("</AppendedData>");
  if (end == std::string_view::npos || end < start) end = bytes.size();
  f.appended = bytes.substr(start, end - start);
  f.appendedStart = start;
  f.appendedBase64 = enc == "base64";
}

} // namespace

RawMesh parseVtu(std::string_view bytes, const std::string& file) {
  VtuFile f;
  f.file = file;
  std::string xml;
  const size_t appendedTag = bytes.find("<AppendedData");
  if (appendedTag == std::string_view::npos) {
    xml = bytes;
  } else {
    xml = std::string(bytes.substr(0, appendedTag)) + "</VTKFile>";
    locateAppendedData(bytes, appendedTag, f);
  }
  tinyxml2::XMLDocument doc;
  if (doc.Parse(xml.data(), xml.size()) != tinyxml2::XML_SUCCESS)
    throw MeshError(file + ":" + std::to_string(doc.ErrorLineNum()) + ": not valid XML: " + doc.ErrorStr());
  const XMLElement* root = doc.RootElement();
  if (!root || std::string_view(root->Name()) != "VTKFile" || !root->Attribute("type", "UnstructuredGrid"))
    throw MeshError(file + ": not a VTK XML UnstructuredGrid file (<VTKFile type=\"UnstructuredGrid\">)");
  const std::string byteOrder = root->Attribute("byte_order") ? root->Attribute("byte_order") : "LittleEndian";
  const std::string headerType = root->Attribute("header_type") ? root->Attribute("header_type") : "UInt32";
  const std::string compressor = root->Attribute("compressor") ? root->Attribute("compressor") : "";
  if (byteOrder != "LittleEndian" && byteOrder != "BigEndian") fail(f, root, "unknown byte_order '" + byteOrder + "'");
  if (headerType != "UInt32" && headerType != "UInt64") fail(f, root, "unknown header_type '" + headerType + "'");
  if (!compressor.empty() && compressor != "vtkZLibDataCompressor")
    fail(f, root, "unsupported compressor '" + compressor + "' (only vtkZLibDataCompressor)");
  f.swap = (byteOrder == "LittleEndian") != hostIsLittleEndian();
  f.headerBytes = headerType == "UInt64" ? 8 : 4;
  f.compressed = !compressor.empty();

  RawMesh out;
  out.source.file = file;
  out.source.positionKind = SourcePositionKind::Record;
  vtk::TetCollector collector(out);
  const XMLElement* grid = child(f, root, "UnstructuredGrid");
  int64_t cellBase = 0;
  for (const XMLElement* piece = child(f, grid, "Piece"); piece; piece = piece->NextSiblingElement("Piece"))
    readPiece(f, piece, out, collector, cellBase);
  collector.finish();
  return out;
}

namespace {

// Writes DataArrays inline (ascii) or into the appended block (raw, UInt64 byte-count headers,
// this machine's byte order).
class VtuWriter {
public:
  explicit VtuWriter(VtuEncoding encoding) : appended_(encoding == VtuEncoding::AppendedRaw) {}

  template <class T>
  void dataArray(const char* type, const std::string& name, int components, const std::vector<T>& values) {
    xml += "        <DataArray type=\"" + std::string(type) + "\" Name=\"" + escapeXml(name) + "\"";
    if (components != 1) xml += " NumberOfComponents=\"" + std::to_string(components) + "\"";
    if (appended_) {
      xml += " format=\"appended\" offset=\"" + std::to_string(data_.size()) + "\"/>\n";
      const uint64_t size = values.size() * sizeof(T);
      data_.append(reinterpret_cast<const char*>(&size), sizeof size);
      data_.append(reinterpret_cast<const char*>(values.data()), size);
      return;
    }
    xml += " format=\"ascii\">\n";
    for (size_t i = 0; i < values.size(); ++i) {
      if (i % static_cast<size_t>(components) == 0) xml += "          ";
      if constexpr (std::is_floating_point_v<T>) vtk::appendNumber(xml, values[i]);
      else vtk::appendNumber(xml, static_cast<int64_t>(values[i]));
      xml += (i + 1) % static_cast<size_t>(components) == 0 ? '\n' : ' ';
    }
    xml += "        </DataArray>\n";
  }

  std::string finish() {
    xml += "  </UnstructuredGrid>\n";
    if (appended_) xml += "  <AppendedData encoding=\"raw\">\n   _" + data_ + "\n  </AppendedData>\n";
    return xml + "</VTKFile>\n";
  }

  std::string xml;

private:
  bool appended_;
  std::string data_;
};

std::vector<double> flatten(const std::vector<Eigen::Vector3d>& vectors) {
  std::vector<double> out;
  out.reserve(3 * vectors.size());
  for (const Eigen::Vector3d& v : vectors) out.insert(out.end(), v.data(), v.data() + 3);
  return out;
}

} // namespace

std::string formatVtu(const TetMesh& mesh, const std::vector<PointField>& fields, VtuEncoding encoding) {
  vtk::checkWritable(mesh, fields, "VTU");
  VtuWriter w(encoding);
  w.xml = std::string("<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"") +
          (hostIsLittleEndian() ? "LittleEndian" : "BigEndian") + "\" header_type=\"UInt64\">\n" +
          "  <UnstructuredGrid>\n    <Piece NumberOfPoints=\"" + std::to_string(mesh.vertexCount()) +
          "\" NumberOfCells=\"" + std::to_string(mesh.tetCount()) + "\">\n";
  if (!fields.empty()) {
    w.xml += "      <PointData Vectors=\"" + escapeXml(fields.front().name) + "\">\n";
    for (const PointField& field : fields) w.dataArray("Float64", field.name, 3, flatten(field.values));
    w.xml += "      </PointData>\n";
  }
  if (!mesh.tetRegion.empty()) {
    w.xml += "      <CellData Scalars=\"region\">\n";
    w.dataArray("Int32", "region", 1, std::vector<int32_t>(mesh.tetRegion.begin(), mesh.tetRegion.end()));
    w.xml += "      </CellData>\n";
  }
  w.xml += "      <Points>\n";
  w.dataArray("Float64", "Points", 3, flatten(mesh.vertices));
  w.xml += "      </Points>\n      <Cells>\n";
  std::vector<int64_t> connectivity, offsets;
  for (const Tet& t : mesh.tets) {
    connectivity.insert(connectivity.end(), t.begin(), t.end());
    offsets.push_back(static_cast<int64_t>(connectivity.size()));
  }
  w.dataArray("Int64", "connectivity", 1, connectivity);
  w.dataArray("Int64", "offsets", 1, offsets);
  w.dataArray("UInt8", "types", 1, std::vector<uint8_t>(mesh.tets.size(), static_cast<uint8_t>(vtk::kTetra)));
  w.xml += "      </Cells>\n    </Piece>\n";
  return w.finish();
}

std::string formatTriangleVtu(const std::vector<float>& positions, const std::vector<unsigned>& triangles,
                              const std::vector<float>& normals) {
  VtuWriter w(VtuEncoding::AppendedRaw);
  const size_t points = positions.size() / 3, cells = triangles.size() / 3;
  w.xml = std::string("<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"") +
          (hostIsLittleEndian() ? "LittleEndian" : "BigEndian") + "\" header_type=\"UInt64\">\n" +
          "  <UnstructuredGrid>\n    <Piece NumberOfPoints=\"" + std::to_string(points) + "\" NumberOfCells=\"" +
          std::to_string(cells) + "\">\n";
  if (!normals.empty()) {
    w.xml += "      <PointData Normals=\"normal\">\n";
    w.dataArray("Float32", "normal", 3, normals);
    w.xml += "      </PointData>\n";
  }
  w.xml += "      <Points>\n";
  w.dataArray("Float32", "Points", 3, positions);
  w.xml += "      </Points>\n      <Cells>\n";
  std::vector<int64_t> connectivity(triangles.begin(), triangles.end()), offsets;
  for (size_t c = 1; c <= cells; ++c) offsets.push_back(static_cast<int64_t>(3 * c));
  w.dataArray("Int64", "connectivity", 1, connectivity);
  w.dataArray("Int64", "offsets", 1, offsets);
  w.dataArray("UInt8", "types", 1, std::vector<uint8_t>(cells, static_cast<uint8_t>(vtk::kTriangle)));
  w.xml += "      </Cells>\n    </Piece>\n";
  return w.finish();
}

} // namespace quiver
