#include "formats/npy.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstring>
#include <limits>
#include <stdexcept>

#include "formats/atomic_file.h"
#include "formats/mesh/byte_cursor.h"
#include "formats/mesh/read_mesh.h"
#include "formats/mesh/text_cursor.h"

namespace quiver {

static_assert(std::numeric_limits<double>::is_iec559 && sizeof(double) == 8, "float64 must be IEEE binary64");
static_assert(std::numeric_limits<float>::is_iec559 && sizeof(float) == 4, "float32 must be IEEE binary32");

namespace {

constexpr std::string_view kMagic("\x93NUMPY", 6);
constexpr size_t kAlignment = 64;  // of the data, as numpy writes it

[[noreturn]] void failHeader(const std::string& file, const std::string& message) {
  throw std::runtime_error(file + ": header: " + message);
}

// Copies `n` bytes, reversing their order when `swap`.
void copyBytes(char* to, const char* from, size_t n, bool swap) {
  std::memcpy(to, from, n);
  if (swap) std::reverse(to, to + n);
}

template <class Float>
double decode(const char* bytes, bool swap) {
  char raw[sizeof(Float)];
  copyBytes(raw, bytes, sizeof(Float), swap);
  Float value;
  std::memcpy(&value, raw, sizeof(Float));
  return value;
}

struct Dtype {
  std::string_view descr;
  size_t size;
  bool littleEndian;
  double (*decode)(const char* bytes, bool swap);
};

constexpr Dtype kDtypes[] = {{"<f8", 8, true, decode<double>},
                             {">f8", 8, false, decode<double>},
                             {"<f4", 4, true, decode<float>},
                             {">f4", 4, false, decode<float>}};

// Python's repr of the shape tuple: "(3,)", "(3, 4)".
std::string shapeText(const std::vector<int64_t>& shape) {
  std::string text = "(";
  for (size_t i = 0; i < shape.size(); ++i) text += (i > 0 ? ", " : "") + std::to_string(shape[i]);
  return text + (shape.size() == 1 ? ",)" : ")");
}

// Element count of a shape whose dimensions are non-negative; false when count × itemSize
// overflows size_t. A zero dimension makes any other one fine.
bool elementCount(const std::vector<int64_t>& shape, size_t itemSize, size_t& count) {
  count = std::find(shape.begin(), shape.end(), 0) == shape.end() ? 1 : 0;
  for (int64_t dim : shape) {
    const auto d = static_cast<size_t>(dim);
    if (count != 0 && d > std::numeric_limits<size_t>::max() / itemSize / count) return false;
    count *= d;
  }
  return true;
}

struct Header {
  std::string_view descr;
  bool fortranOrder = false;
  std::vector<int64_t> shape;
};

// The header's Python dict literal: string keys, string/bool/integer-tuple values, any spacing,
// trailing commas. `python2Longs` accepts the "3L" integers that Python 2 wrote in versions 1.0/2.0.
class HeaderParser {
public:
  HeaderParser(std::string_view text, size_t offset, const std::string& file, bool python2Longs)
      : text_(text), offset_(offset), file_(file), python2Longs_(python2Longs) {}

  Header parse() {
    static constexpr std::string_view kKeys[] = {"descr", "fortran_order", "shape"};
    bool seen[3] = {};
    Header header;
    expect('{', "at the start of the header");
    while (!next('}')) {
      const std::string_view key = string("a key");
      const size_t k = std::find(std::begin(kKeys), std::end(kKeys), key) - std::begin(kKeys);
      if (k == 3) fail("unexpected key '" + printableToken(key) + "' (expected descr, fortran_order and shape)");
      if (seen[k]) fail("key '" + std::string(key) + "' appears twice");
      seen[k] = true;
      expect(':', "after '" + std::string(key) + "'");
      if (k == 0) {
        if (next('[')) fail("'descr' is a structured dtype, which is not supported (need float64 or float32)");
        header.descr = string("'descr'");
      } else if (k == 1) {
        header.fortranOrder = boolean();
      } else {
        header.shape = tuple();
      }
      if (next(','))
        ++pos_;
      else if (!next('}'))
        fail("expected ',' or '}' after the value of '" + std::string(key) + "', found " + found());
    }
    ++pos_;
    if (!atEnd()) fail("unexpected " + found() + " after the closing '}'");
    for (size_t k = 0; k < 3; ++k)
      if (!seen[k]) failHeader(file_, "key '" + std::string(kKeys[k]) + "' is missing");
    return header;
  }

private:
  void skipBlanks() {
    while (pos_ < text_.size() && std::string_view(" \t\n\r\f\v").find(text_[pos_]) != std::string_view::npos) ++pos_;
  }
  bool atEnd() {
    skipBlanks();
    return pos_ == text_.size();
  }
  // The next non-blank character is `c`.
  bool next(char c) { return !atEnd() && text_[pos_] == c; }

  std::string found() { return atEnd() ? "the end of the header" : "'" + printableToken(text_.substr(pos_, 1)) + "'"; }

  void expect(char c, const std::string& where) {
    if (!next(c)) fail(std::string("expected '") + c + "' " + where + ", found " + found());
    ++pos_;
  }

  std::string_view string(const char* what) {
    if (!next('\'') && !next('"')) fail(std::string("expected a quoted string for ") + what + ", found " + found());
    const char quote = text_[pos_];
    const size_t start = ++pos_;
    const size_t end = text_.find_first_of(std::string("\\\n") + quote, start);
    if (end == std::string_view::npos || text_[end] != quote)
      fail(std::string("unterminated string (or one with an escape) for ") + what);
    pos_ = end + 1;
    return text_.substr(start, end - start);
  }

  bool boolean() {
    skipBlanks();
    const size_t start = pos_;
    while (pos_ < text_.size() && std::isalnum(static_cast<unsigned char>(text_[pos_]))) ++pos_;
    const std::string_view word = text_.substr(start, pos_ - start);
    if (word != "True" && word != "False") {
      pos_ = start;
      fail("'fortran_order' must be True or False, found " + found());
    }
    return word == "True";
  }

  std::vector<int64_t> tuple() {
    std::vector<int64_t> shape;
    bool comma = false;
    expect('(', "to start 'shape'");
    while (!next(')')) {
      shape.push_back(integer());
      comma = next(',');
      if (comma)
        ++pos_;
      else if (!next(')'))
        fail("expected ',' or ')' in 'shape', found " + found());
    }
    ++pos_;
    if (shape.size() == 1 && !comma) fail("'shape' is a number, not a tuple (a 1-D shape is written (n,))");
    return shape;
  }

  int64_t integer() {
    skipBlanks();
    const size_t start = pos_;
    int64_t value = 0;
    const auto [end, ec] = std::from_chars(text_.data() + start, text_.data() + text_.size(), value);
    if (ec == std::errc::result_out_of_range) fail("a 'shape' entry does not fit in 64 bits");
    if (ec != std::errc()) fail("expected an integer in 'shape', found " + found());
    pos_ = end - text_.data();
    if (python2Longs_ && pos_ < text_.size() && text_[pos_] == 'L') ++pos_;
    return value;
  }

  [[noreturn]] void fail(const std::string& message) const {
    throw std::runtime_error(file_ + ": byte " + std::to_string(offset_ + pos_) + ": header: " + message);
  }

  std::string_view text_;
  size_t offset_;  // of the header in the file
  const std::string& file_;
  bool python2Longs_;
  size_t pos_ = 0;
};

} // namespace

std::string formatNpy(const std::vector<int64_t>& shape, const double* data) {
  size_t count = 0;
  if (shape.empty() || shape.size() > 2 || std::any_of(shape.begin(), shape.end(), [](int64_t d) { return d < 0; }) ||
      !elementCount(shape, sizeof(double), count))
    throw std::invalid_argument("formatNpy: " + shapeText(shape) + " is not the shape of a 1-D or 2-D array");
  std::string header = "{'descr': '<f8', 'fortran_order': False, 'shape': " + shapeText(shape) + ", }";
  // Version 1.0 (2-byte header length: the header is under 200 bytes), padded so that the data
  // starts at a multiple of kAlignment.
  const size_t unpadded = kMagic.size() + 2 + 2 + header.size() + 1;
  header.append((kAlignment - unpadded % kAlignment) % kAlignment, ' ');
  header += '\n';
  std::string out(kMagic);
  out += {'\x01', '\x00', static_cast<char>(header.size() & 0xff), static_cast<char>(header.size() >> 8)};
  out += header;
  const size_t start = out.size();
  out.resize(start + count * sizeof(double));
  const bool swap = !hostIsLittleEndian();
  for (size_t i = 0; i < count; ++i)
    copyBytes(&out[start + i * sizeof(double)], reinterpret_cast<const char*>(data + i), sizeof(double), swap);
  return out;
}

NpyArray parseNpy(std::string_view bytes, const std::string& file) {
  const std::string_view head = bytes.substr(0, kMagic.size());
  ByteCursor cursor(bytes, 0, file, !hostIsLittleEndian());
  if (head != kMagic.substr(0, head.size())) cursor.fail("not a .npy file (it does not start with \\x93NUMPY)");
  cursor.skip(kMagic.size(), "the magic string");
  const auto major = cursor.read<uint8_t>("the format version");
  const auto minor = cursor.read<uint8_t>("the format version");
  if (major < 1 || major > 3 || minor != 0)
    cursor.failAt(kMagic.size(), "format version " + std::to_string(major) + "." + std::to_string(minor) +
                                     " is not supported (1.0, 2.0 or 3.0)");
  const size_t lengthAt = cursor.position();
  const size_t length =
      major == 1 ? cursor.read<uint16_t>("the header length") : cursor.read<uint32_t>("the header length");
  if (length > cursor.remaining())
    cursor.failAt(lengthAt, "header length " + std::to_string(length) + " runs past the end of the file (" +
                                std::to_string(bytes.size()) + " bytes)");
  const std::string_view text = bytes.substr(cursor.position(), length);
  if (text.empty() || text.back() != '\n') cursor.fail("header does not end with a newline");
  const Header header = HeaderParser(text, cursor.position(), file, major < 3).parse();
  cursor.skip(length, "the header");

  const Dtype* dtype = std::find_if(std::begin(kDtypes), std::end(kDtypes),
                                    [&](const Dtype& d) { return d.descr == header.descr; });
  if (dtype == std::end(kDtypes))
    failHeader(file, "dtype '" + printableToken(header.descr) + "' is not supported (need float64 or float32)");
  const std::string shape = printableToken(shapeText(header.shape));
  if (header.shape.empty()) failHeader(file, "shape () is that of a scalar (need a 1-D or 2-D array)");
  if (header.shape.size() > 2)
    failHeader(file, "shape " + shape + " has " + std::to_string(header.shape.size()) + " dimensions (need 1 or 2)");
  if (std::any_of(header.shape.begin(), header.shape.end(), [](int64_t d) { return d < 0; }))
    failHeader(file, "shape " + shape + " has a negative dimension");
  size_t count = 0;
  if (!elementCount(header.shape, dtype->size, count))
    failHeader(file, "shape " + shape + " of '" + std::string(dtype->descr) +
                         "' is too large: its byte count overflows size_t");
  if (count * dtype->size != cursor.remaining())
    cursor.fail("expected " + std::to_string(count * dtype->size) + " bytes of data for shape " + shape + " of '" +
                std::string(dtype->descr) + "', found " + std::to_string(cursor.remaining()) +
                (count * dtype->size > cursor.remaining() ? " (truncated file)" : " (trailing bytes)"));

  NpyArray array{header.shape, std::vector<double>(count)};
  const bool swap = dtype->littleEndian != hostIsLittleEndian();
  const size_t rows = static_cast<size_t>(header.shape[0]);
  const size_t cols = count == 0 ? 0 : count / rows;
  const char* data = bytes.data() + cursor.position();
  // Fortran order stores element (i, j) at j * rows + i.
  for (size_t k = 0; k < count; ++k)
    array.data[header.fortranOrder ? (k % rows) * cols + k / rows : k] = dtype->decode(data + k * dtype->size, swap);
  return array;
}

void writeNpy(const std::string& path, const std::vector<int64_t>& shape, const double* data) {
  writeFileAtomically(path, formatNpy(shape, data));
}

NpyArray readNpy(const std::string& path) { return parseNpy(readFileBytes(path), path); }

} // namespace quiver
