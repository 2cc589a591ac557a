#include "formats/mesh/own_readers.h"

#include <cmath>
#include <cstdint>
#include <string_view>
#include <unordered_set>
#include <vector>

#include "common/mesh_error.h"
#include "formats/mesh/byte_cursor.h"
#include "formats/mesh/number_format.h"
#include "formats/mesh/text_cursor.h"

namespace quiver {

namespace {

enum class Type { Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32, Float64 };

bool typeNamed(std::string_view name, Type& type) {
  static const std::pair<std::string_view, Type> kNames[] = {
      {"char", Type::Int8},     {"int8", Type::Int8},     {"uchar", Type::UInt8},     {"uint8", Type::UInt8},
      {"short", Type::Int16},   {"int16", Type::Int16},   {"ushort", Type::UInt16},   {"uint16", Type::UInt16},
      {"int", Type::Int32},     {"int32", Type::Int32},   {"uint", Type::UInt32},     {"uint32", Type::UInt32},
      {"float", Type::Float32}, {"float32", Type::Float32}, {"double", Type::Float64}, {"float64", Type::Float64}};
  for (const auto& [n, t] : kNames)
    if (n == name) {
      type = t;
      return true;
    }
  return false;
}

size_t sizeOf(Type t) {
  switch (t) {
    case Type::Int8: case Type::UInt8: return 1;
    case Type::Int16: case Type::UInt16: return 2;
    case Type::Int32: case Type::UInt32: case Type::Float32: return 4;
    case Type::Float64: return 8;
  }
  return 1;
}

bool integral(Type t) { return t != Type::Float32 && t != Type::Float64; }

// A value read as a count or an index, for a message: any double, without converting one too
// large for an integer type.
std::string integerText(double v) { return std::fabs(v) < 1e15 ? std::to_string(static_cast<long long>(v)) : formatReal(v); }

struct Property {
  std::string name;
  Type type = Type::Float32;
  bool list = false;
  Type countType = Type::UInt8;
};

struct Element {
  std::string name;
  int64_t count = 0;
  std::vector<Property> properties;
};

enum class Format { Ascii, LittleEndian, BigEndian };

struct Header {
  Format format = Format::Ascii;
  std::vector<Element> elements;
  size_t bodyStart = 0;
};

Header readHeader(TextCursor& in) {
  if (in.restOfLine() != "ply") in.fail("not a PLY file: it must begin with the line 'ply'");
  Header h;
  bool formatSeen = false;
  std::unordered_set<std::string> names;
  for (;;) {
    if (in.position() >= in.text().size()) in.fail("the header has no end_header line");
    const std::string_view line = in.restOfLine();
    const std::vector<std::string_view> w = words(line);
    if (w.empty() || w[0] == "comment" || w[0] == "obj_info") continue;
    if (w[0] == "end_header") break;
    if (w[0] == "format") {
      if (w.size() != 3 || w[2] != "1.0") in.fail("expected 'format ascii|binary_little_endian|binary_big_endian 1.0'");
      if (w[1] == "ascii") h.format = Format::Ascii;
      else if (w[1] == "binary_little_endian") h.format = Format::LittleEndian;
      else if (w[1] == "binary_big_endian") h.format = Format::BigEndian;
      else in.fail("unknown format '" + printableToken(w[1]) + "'");
      formatSeen = true;
    } else if (w[0] == "element") {
      int64_t count = -1;
      if (w.size() != 3 || !parseInteger(w[2], count) || count < 0 || count > INT32_MAX)
        in.fail("expected 'element NAME COUNT' with a count from 0 to " + std::to_string(INT32_MAX));
      if (!names.insert(std::string(w[1])).second) in.fail("element '" + printableToken(w[1]) + "' is defined twice");
      h.elements.push_back({std::string(w[1]), count, {}});
    } else if (w[0] == "property") {
      if (h.elements.empty()) in.fail("a property before any element");
      Property p;
      const bool list = w.size() == 5 && w[1] == "list";
      if (list ? !(typeNamed(w[2], p.countType) && integral(p.countType) && typeNamed(w[3], p.type))
               : !(w.size() == 3 && typeNamed(w[1], p.type)))
        in.fail("expected 'property TYPE NAME' or 'property list COUNT_TYPE TYPE NAME' with PLY types (a list's count "
                "type integral), found '" + printableToken(line) + "'");
      p.list = list;
      p.name = std::string(w.back());
      h.elements.back().properties.push_back(p);
    }  // other lines are skipped, as Assimp skips them: Blender 2.4 wrote comments without the keyword
  }
  if (!formatSeen) in.fail("the header has no format line");
  h.bodyStart = in.position();
  return h;
}

// Reads one value of the body, ASCII or binary, as a double (every PLY type is exact in one).
class Body {
public:
  Body(std::string_view bytes, const Header& h, const std::string& name)
      : ascii_(h.format == Format::Ascii), text_(bytes, name),
        binary_(bytes, h.bodyStart, name, (h.format == Format::BigEndian) == hostIsLittleEndian()) {
    if (ascii_) text_.seek(h.bodyStart);
  }

  double value(Type t, const char* what) {
    if (ascii_) {
      const double v = text_.real(what);
      if (integral(t) && v != std::floor(v)) text_.fail(std::string(what) + " " + formatReal(v) + " is not an integer");
      return v;
    }
    switch (t) {
      case Type::Int8: return binary_.read<int8_t>(what);
      case Type::UInt8: return binary_.read<uint8_t>(what);
      case Type::Int16: return binary_.read<int16_t>(what);
      case Type::UInt16: return binary_.read<uint16_t>(what);
      case Type::Int32: return binary_.read<int32_t>(what);
      case Type::UInt32: return binary_.read<uint32_t>(what);
      case Type::Float32: return binary_.read<float>(what);
      case Type::Float64: return binary_.read<double>(what);
    }
    return 0;
  }

  // A list's length, bounded by what the bytes left could hold of its items (at least one byte each
  // in ASCII, the type's size in binary), so that no count can run a loop past the file's end.
  int64_t length(const Property& p) {
    const size_t at = position();
    const double n = value(p.countType, p.name.c_str());
    const double room = ascii_ ? double(text_.text().size() - text_.position()) : double(binary_.remaining() / sizeOf(p.type));
    if (n < 0) failAt(at, "the list " + p.name + " counts " + integerText(n) + " items");
    if (n > room || n > INT32_MAX)
      failAt(at, "the list " + p.name + " counts " + integerText(n) + " items, more than the bytes left in the file can hold");
    return static_cast<int64_t>(n);
  }

  // Where the next value starts (a byte offset), for failAt(): in ASCII the line of the value read
  // last names the place.
  size_t position() const { return ascii_ ? text_.position() : binary_.position(); }
  [[noreturn]] void failAt(size_t at, const std::string& message) const {
    if (ascii_) text_.fail(message);
    binary_.failAt(at, message);
  }

private:
  bool ascii_;
  TextCursor text_;
  ByteCursor binary_;
};

bool isIndexList(const Element& e, const Property& p) {
  return (e.name == "face" || e.name == "tristrips") && p.list && (p.name == "vertex_indices" || p.name == "vertex_index");
}

// A triangle strip's triangles, every other one turned so that all wind alike; degenerate ones
// (a repeated vertex, as strips use to join) dropped.
void addStrip(const std::vector<unsigned>& strip, PolygonMesh& out) {
  for (size_t k = 0; k + 2 < strip.size(); ++k) {
    unsigned a = strip[k], b = strip[k + 1];
    const unsigned c = strip[k + 2];
    if (k % 2) std::swap(a, b);
    if (a == b || b == c || a == c) continue;
    out.faceSizes.push_back(3);
    out.indices.insert(out.indices.end(), {a, b, c});
  }
}

int indexOf(const Element& e, std::string_view name) {
  for (size_t i = 0; i < e.properties.size(); ++i)
    if (e.properties[i].name == name && !e.properties[i].list) return static_cast<int>(i);
  return -1;
}

} // namespace

PolygonMesh readPly(std::string_view bytes, const std::string& name) {
  TextCursor headerText(bytes, name);
  const Header h = readHeader(headerText);
  const Element* vertices = nullptr;
  for (const Element& e : h.elements)
    if (e.name == "vertex") vertices = &e;
  if (!vertices) headerText.fail("the header defines no vertex element");
  const int xyz[3] = {indexOf(*vertices, "x"), indexOf(*vertices, "y"), indexOf(*vertices, "z")};
  if (xyz[0] < 0 || xyz[1] < 0 || xyz[2] < 0) headerText.fail("the vertex element lacks one of the properties x, y, z");
  const int normal[3] = {indexOf(*vertices, "nx"), indexOf(*vertices, "ny"), indexOf(*vertices, "nz")};
  const bool hasNormals = normal[0] >= 0 && normal[1] >= 0 && normal[2] >= 0;
  for (const Element& e : h.elements)
    for (const Property& p : e.properties)
      if (isIndexList(e, p) && !integral(p.type))
        headerText.fail("the " + e.name + " element's " + p.name + " list must have an integer type");
  int uv[2] = {-1, -1};
  for (const auto& [u, v] : {std::pair{"s", "t"}, {"u", "v"}, {"texture_u", "texture_v"}, {"texture_s", "texture_t"}})
    if (uv[0] < 0 && indexOf(*vertices, u) >= 0 && indexOf(*vertices, v) >= 0) uv[0] = indexOf(*vertices, u), uv[1] = indexOf(*vertices, v);

  PolygonMesh out;
  Body body(bytes, h, name);
  std::vector<double> values;
  std::vector<unsigned> strip;
  for (const Element& e : h.elements) {
    if (e.properties.empty()) continue;  // its instances hold no bytes
    const bool isVertex = &e == vertices, isStrips = e.name == "tristrips";
    for (int64_t i = 0; i < e.count; ++i) {
      const size_t start = body.position();
      values.assign(e.properties.size(), 0.0);
      for (size_t p = 0; p < e.properties.size(); ++p) {
        const Property& prop = e.properties[p];
        if (!prop.list) {
          values[p] = body.value(prop.type, prop.name.c_str());
          continue;
        }
        const int64_t n = body.length(prop);
        const bool indices = isIndexList(e, prop);
        if (indices && !isStrips) out.faceSizes.push_back(static_cast<unsigned>(n));
        strip.clear();
        for (int64_t k = 0; k < n; ++k) {
          const size_t at = body.position();
          const double index = body.value(prop.type, prop.name.c_str());
          if (!indices) continue;
          if (isStrips && index == -1) {  // a strip ends, the next begins
            addStrip(strip, out);
            strip.clear();
            continue;
          }
          if (index < 0 || index >= double(vertices->count))
            body.failAt(at, e.name + " " + std::to_string(i) + ": vertex index " + integerText(index) + " is out of range [0, " +
                            std::to_string(vertices->count) + ")");
          (isStrips ? strip : out.indices).push_back(static_cast<unsigned>(index));
        }
        if (indices && isStrips) addStrip(strip, out);
      }
      if (!isVertex) continue;
      for (int c = 0; c < 3; ++c) {
        const float x = toFloat(values[xyz[c]]);
        if (!std::isfinite(x))
          body.failAt(start, "vertex " + std::to_string(i) + ": coordinate " + formatReal(values[xyz[c]]) + " is not a finite float");
        out.positions.push_back(x);
      }
      if (hasNormals)
        for (int c = 0; c < 3; ++c) out.normals.push_back(toFloat(values[normal[c]]));
      if (uv[0] >= 0)
        for (int c = 0; c < 2; ++c) out.uvs.push_back(toFloat(values[uv[c]]));
    }
  }
  return out;
}

} // namespace quiver
