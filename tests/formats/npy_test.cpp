// .npy reader and writer: bit-exact round trips, hand-built files (versions 1.0-3.0, header
// spellings, Fortran order, both byte orders, float32), files numpy wrote, numpy reading ours,
// and bad input.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include <gtest/gtest.h>

#include "formats/npy.h"
#include "tests/support/test_support.h"

namespace quiver {
namespace {

using Shapes = std::vector<std::vector<int64_t>>;

const std::string kFile = "test.npy";
const char* const kPython = "/usr/bin/python3";

double fromBits(uint64_t bits) {
  double value;
  std::memcpy(&value, &bits, sizeof value);
  return value;
}

// The bytes of `words` (IEEE bit patterns, e.g. uint64_t for float64), each in the given order.
template <class Word>
std::string encoded(std::initializer_list<Word> words, bool bigEndian) {
  std::string out;
  for (Word w : words)
    for (size_t i = 0; i < sizeof(Word); ++i) {
      const size_t shift = 8 * (bigEndian ? sizeof(Word) - 1 - i : i);
      out += static_cast<char>((w >> shift) & 0xff);
    }
  return out;
}

// A .npy file built by hand: magic, version major.0, the header length (little-endian, 2 bytes in
// version 1 and 4 after), `dict` padded with blanks and a newline to a 64-byte preamble, `data`.
std::string npyFile(int major, const std::string& dict, const std::string& data) {
  const size_t lengthBytes = major == 1 ? 2 : 4;
  std::string header = dict;
  while ((6 + 2 + lengthBytes + header.size() + 1) % 64 != 0) header += ' ';
  header += '\n';
  std::string out = std::string("\x93NUMPY", 6) + static_cast<char>(major) + '\0';
  for (size_t i = 0; i < lengthBytes; ++i) out += static_cast<char>((header.size() >> (8 * i)) & 0xff);
  return out + header + data;
}

std::string dictOf(const std::string& descr, const std::string& shape, bool fortran = false) {
  return "{'descr': '" + descr + "', 'fortran_order': " + (fortran ? "True" : "False") + ", 'shape': " + shape + ", }";
}

// Same size and the same bits, element by element (so -0.0 and NaN payloads count).
void expectSameBits(const std::vector<double>& actual, const std::vector<double>& expected) {
  ASSERT_EQ(actual.size(), expected.size());
  for (size_t i = 0; i < expected.size(); ++i)
    EXPECT_EQ(std::memcmp(&actual[i], &expected[i], sizeof(double)), 0)
        << "element " << i << ": " << actual[i] << " != " << expected[i];
}

void expectArray(const NpyArray& array, const std::vector<int64_t>& shape, const std::vector<double>& data) {
  EXPECT_EQ(array.shape, shape);
  expectSameBits(array.data, data);
}

// The message of the std::runtime_error parseNpy throws, or "" when it returns.
std::string errorOf(std::string_view bytes) {
  try {
    parseNpy(bytes, kFile);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

// parseNpy fails with a message that starts "test.npy: <where>: " and contains `what`.
void expectError(std::string_view bytes, const std::string& where, const std::string& what) {
  const std::string message = errorOf(bytes);
  const std::string prefix = kFile + ": " + where + ": ";
  EXPECT_EQ(message.compare(0, prefix.size(), prefix), 0) << "expected '" << prefix << "...', got '" << message << "'";
  EXPECT_NE(message.find(what), std::string::npos) << "expected '" << what << "' in '" << message << "'";
}

// Every value class a float64 can hold, with two NaN payloads and a signalling NaN.
const std::vector<double> kSpecial = {
    1.0,
    -0.0,
    0.0,
    std::numeric_limits<double>::denorm_min(),
    fromBits(0x000fedcba9876543),  // a larger denormal
    fromBits(0x7ff8000000abcdef),  // quiet NaN with a payload
    fromBits(0x7ff0000000000001),  // signalling NaN
    fromBits(0xfff8000000000000),  // negative NaN
    std::numeric_limits<double>::infinity(),
    -std::numeric_limits<double>::infinity(),
    std::numeric_limits<double>::max(),
    0.1,
};

TEST(Npy, RoundTripKeepsEveryBit) {
  for (const std::vector<int64_t>& shape : Shapes{{12}, {3, 4}, {4, 3}, {12, 1}, {1, 12}}) {
    SCOPED_TRACE(testing::PrintToString(shape));
    const std::string bytes = formatNpy(shape, kSpecial.data());
    const size_t headerLength = static_cast<unsigned char>(bytes[8]) | static_cast<unsigned char>(bytes[9]) << 8;
    EXPECT_EQ((10 + headerLength) % 64, 0u) << "the data should start 64-byte aligned";
    EXPECT_EQ(bytes.size(), 10 + headerLength + kSpecial.size() * sizeof(double));
    expectArray(parseNpy(bytes, kFile), shape, kSpecial);
  }
}

TEST(Npy, RoundTripOfEmptyArrays) {
  for (const std::vector<int64_t>& shape : Shapes{{0}, {0, 3}, {3, 0}, {int64_t{1} << 62, 0}})
    expectArray(parseNpy(formatNpy(shape, nullptr), kFile), shape, {});
}

TEST(Npy, WriteAndReadAFile) {
  const std::string path = test::tempDir("npy_write_read") + "/basis.npy";
  writeNpy(path, {4, 3}, kSpecial.data());
  expectArray(readNpy(path), {4, 3}, kSpecial);

  const std::string missing = test::tempDir("npy_missing") + "/absent.npy";
  try {
    readNpy(missing);
    ADD_FAILURE() << "reading a missing file should throw";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(missing), std::string::npos) << e.what();
  }
}

TEST(Npy, WriterRefusesShapesItCannotWrite) {
  const double value = 1.0;
  EXPECT_THROW(formatNpy({}, &value), std::invalid_argument);
  EXPECT_THROW(formatNpy({1, 1, 1}, &value), std::invalid_argument);
  EXPECT_THROW(formatNpy({-1}, &value), std::invalid_argument);
  EXPECT_THROW(formatNpy({int64_t{1} << 40, int64_t{1} << 40}, &value), std::invalid_argument);
}

// 1.5, -2.0 and 0.1 as float64 bit patterns.
const std::initializer_list<uint64_t> kF8Bits = {0x3ff8000000000000, 0xc000000000000000, 0x3fb999999999999a};
const std::vector<double> kF8Values = {1.5, -2.0, 0.1};

TEST(Npy, ReadsEveryHeaderSpelling) {
  const std::string data = encoded(kF8Bits, false) + encoded(kF8Bits, false);
  const std::vector<double> expected = {1.5, -2.0, 0.1, 1.5, -2.0, 0.1};
  for (const char* dict : {"{'descr': '<f8', 'fortran_order': False, 'shape': (2, 3), }",
                           "{'shape':(2,3),'descr':'<f8','fortran_order':False}",
                           "{ \"fortran_order\" : False ,\n\t\"shape\" : ( 2 , 3 , ) , \"descr\" : \"<f8\" , }"})
    for (int major : {1, 2, 3}) {
      SCOPED_TRACE(std::string(dict) + " in version " + std::to_string(major));
      expectArray(parseNpy(npyFile(major, dict, data), kFile), {2, 3}, expected);
    }
}

TEST(Npy, ReadsPython2LongsInVersions1And2Only) {
  const std::string dict = "{'descr': '<f8', 'fortran_order': False, 'shape': (1L, 3L), }";
  const std::string data = encoded(kF8Bits, false);
  expectArray(parseNpy(npyFile(1, dict, data), kFile), {1, 3}, kF8Values);
  expectArray(parseNpy(npyFile(2, dict, data), kFile), {1, 3}, kF8Values);
  expectError(npyFile(3, dict, data), "byte " + std::to_string(12 + dict.find("L, 3L")), "found 'L'");
}

TEST(Npy, OneDimensionalShapeIsATuple) {
  const std::string data = encoded(kF8Bits, false);
  expectArray(parseNpy(npyFile(1, dictOf("<f8", "(3,)"), data), kFile), {3}, kF8Values);
  const std::string dict = dictOf("<f8", "(3)");
  expectError(npyFile(1, dict, data), "byte " + std::to_string(10 + dict.find(')') + 1),
              "'shape' is a number, not a tuple");
}

TEST(Npy, FortranOrderIsTransposedToRowMajor) {
  // Column by column: the 2x3 matrix [[1, 2, 3], [4, 5, 6]] and the 3x2 matrix [[1, 2], [3, 4], [5, 6]].
  const std::string wide = encoded<uint64_t>({0x3ff0000000000000, 0x4010000000000000, 0x4000000000000000,
                                              0x4014000000000000, 0x4008000000000000, 0x4018000000000000},
                                             false);
  expectArray(parseNpy(npyFile(1, dictOf("<f8", "(2, 3)", true), wide), kFile), {2, 3}, {1, 2, 3, 4, 5, 6});
  const std::string tall = encoded<uint64_t>({0x3ff0000000000000, 0x4008000000000000, 0x4014000000000000,
                                              0x4000000000000000, 0x4010000000000000, 0x4018000000000000},
                                             false);
  expectArray(parseNpy(npyFile(1, dictOf("<f8", "(3, 2)", true), tall), kFile), {3, 2}, {1, 2, 3, 4, 5, 6});
  expectArray(parseNpy(npyFile(1, dictOf("<f8", "(3,)", true), encoded(kF8Bits, false)), kFile), {3}, kF8Values);
}

TEST(Npy, ReadsBigEndianFloat64) {
  const std::string data("\x3f\xf8\0\0\0\0\0\0"
                         "\xc0\0\0\0\0\0\0\0"
                         "\x3f\xb9\x99\x99\x99\x99\x99\x9a",
                         24);
  EXPECT_EQ(data, encoded(kF8Bits, true));
  expectArray(parseNpy(npyFile(1, dictOf(">f8", "(3,)"), data), kFile), {3}, kF8Values);
  expectArray(parseNpy(npyFile(1, dictOf(">f8", "(1, 3)", true), data), kFile), {1, 3}, kF8Values);
}

TEST(Npy, ReadsFloat32InBothByteOrders) {
  // 1.5f, -0.25f, 0.1f.
  const std::string little("\0\0\xc0\x3f"
                           "\0\0\x80\xbe"
                           "\xcd\xcc\xcc\x3d",
                           12);
  const std::vector<double> expected = {1.5, -0.25, static_cast<double>(0.1f)};
  expectArray(parseNpy(npyFile(1, dictOf("<f4", "(3,)"), little), kFile), {3}, expected);
  const std::string big = encoded<uint32_t>({0x3fc00000, 0xbe800000, 0x3dcccccd}, true);
  expectArray(parseNpy(npyFile(2, dictOf(">f4", "(3, 1)"), big), kFile), {3, 1}, expected);
}

// Files numpy wrote (tests/assets/npy/make_fixtures.py); the values are typed from that script.
TEST(Npy, ReadsFilesNumpyWrote) {
  const auto read = [](const char* name) { return readNpy(test::asset(std::string("npy/") + name)); };
  expectArray(read("c_order_3x2.npy"), {3, 2}, {1.5, -2.25, 3.0, 0.1, -0.0, 5e-324});
  expectArray(read("fortran_3x2.npy"), {3, 2}, {1.25, 2.5, 3.75, 5.0, 6.25, 7.5});
  expectArray(read("float32_vector.npy"), {4},
              {static_cast<double>(0.1f), -1.5, static_cast<double>(std::numeric_limits<float>::max()),
               static_cast<double>(std::numeric_limits<float>::denorm_min())});
  expectArray(read("big_endian_2x2.npy"), {2, 2}, {1.0, -2.5, std::numeric_limits<double>::infinity(), 1e300});
  expectArray(read("version2.npy"), {4}, {0.0, 0.5, 1.0, 1.5});
  expectArray(read("version3.npy"), {4}, {0.0, 0.5, 1.0, 1.5});
}

// numpy loads what formatNpy writes as '<f8' with the same shape and the same bytes.
TEST(Npy, NumpyReadsWhatWeWrite) {
  if (std::system((std::string(kPython) + " -c 'import numpy' >/dev/null 2>&1").c_str()) != 0)
    GTEST_SKIP() << kPython << " with numpy is not available: skipping the cross-check";
  const std::string folder = test::tempDir("npy_numpy_reads");
  const std::string check =
      "import sys, numpy as np; a = np.load(sys.argv[1]); "
      "shape = tuple(int(n) for n in sys.argv[2].split(',')); "
      "ok = a.dtype == np.dtype('<f8') and a.shape == shape and a.tobytes() == bytes.fromhex(sys.argv[3]); "
      "ok or print('numpy read', a.dtype, a.shape, a, file=sys.stderr); sys.exit(0 if ok else 1)";
  for (const std::vector<int64_t>& shape : Shapes{{12}, {4, 3}, {1, 12}, {0, 5}}) {
    SCOPED_TRACE(testing::PrintToString(shape));
    const std::string path = folder + "/a.npy";
    writeNpy(path, shape, kSpecial.data());
    const size_t count = static_cast<size_t>(shape.size() == 1 ? shape[0] : shape[0] * shape[1]);
    std::string hex;
    for (size_t i = 0; i < count * sizeof(double); ++i) {
      char byte[3];
      std::snprintf(byte, sizeof byte, "%02x", reinterpret_cast<const unsigned char*>(kSpecial.data())[i]);
      hex += byte;
    }
    const std::string dims = shape.size() == 1 ? std::to_string(shape[0])
                                               : std::to_string(shape[0]) + "," + std::to_string(shape[1]);
    const std::string command =
        std::string(kPython) + " -c \"" + check + "\" '" + path + "' '" + dims + "' '" + hex + "'";
    EXPECT_EQ(std::system(command.c_str()), 0) << command;
  }
}

TEST(Npy, EveryTruncationFails) {
  const std::vector<std::string> files = {formatNpy({3, 2}, kSpecial.data()),
                                          npyFile(2, dictOf(">f4", "(2,)"), encoded<uint32_t>({1, 2}, true))};
  for (const std::string& file : files)
    for (size_t k = 0; k < file.size(); ++k) {
      // Each prefix sits in a buffer of exactly its size, so that over-reads are real ones.
      std::unique_ptr<char[]> buffer(new char[k]);
      std::memcpy(buffer.get(), file.data(), k);
      const std::string message = errorOf(std::string_view(buffer.get(), k));
      EXPECT_EQ(message.compare(0, kFile.size() + 2, kFile + ": "), 0) << "cut after " << k << ": '" << message << "'";
    }
}

TEST(Npy, RefusesBadPreambles) {
  const std::string good = npyFile(1, dictOf("<f8", "(3,)"), encoded(kF8Bits, false));
  expectError("", "byte 0", "unexpected end of file");
  expectError("PK\x03\x04", "byte 0", "not a .npy file");
  expectError("\x93NUMPZ" + good.substr(6), "byte 0", "not a .npy file");
  for (const char* version : {"\x04\x00", "\x01\x01", "\x00\x00"}) {
    std::string bytes = good;
    bytes.replace(6, 2, version, 2);
    expectError(bytes, "byte 6", "format version " + std::to_string(version[0]) + "." + std::to_string(version[1]) +
                                     " is not supported");
  }
  // Version 2.0 with a 4-byte header length of 70000 in a 120-byte file.
  const std::string longHeader = std::string("\x93NUMPY\x02\x00", 8) + encoded<uint32_t>({70000}, false) +
                                 std::string(108, ' ');
  EXPECT_EQ(errorOf(longHeader), "test.npy: byte 8: header length 70000 runs past the end of the file (120 bytes)");

  std::string unterminated = good;
  unterminated[good.size() - 3 * sizeof(double) - 1] = ' ';  // the newline before the data
  expectError(unterminated, "byte 10", "header does not end with a newline");
  std::string shortLength = good;
  shortLength[8] = 40;  // ends the header inside the dict
  expectError(shortLength, "byte 10", "header does not end with a newline");
}

TEST(Npy, RefusesBadHeaders) {
  const std::string data = encoded(kF8Bits, false);
  const struct {
    std::string dict, what;
  } cases[] = {
      {"{'descr': '<f8', 'shape': (3,), }", "key 'fortran_order' is missing"},
      {"{'descr': '<f8', 'fortran_order': False, 'shape': (3,), 'extra': 1}", "unexpected key 'extra'"},
      {"{'descr': '<f8', 'fortran_order': False, 'descr': '<f8', 'shape': (3,)}", "key 'descr' appears twice"},
      {"{'descr': '<f8', 'fortran_order': 0, 'shape': (3,)}", "'fortran_order' must be True or False, found '0'"},
      {"{'descr': '<f8', 'fortran_order': False, 'shape': [3]}", "expected '(' to start 'shape', found '['"},
      {"{'descr': '<f8', 'fortran_order': False, 'shape': (3, x)}", "expected an integer in 'shape', found 'x'"},
      {"{'descr': '<f8', 'fortran_order': False, 'shape': (3 3)}", "expected ',' or ')' in 'shape', found '3'"},
      {"{'descr': '<f8', 'fortran_order': False, 'shape': (99999999999999999999,)}", "does not fit in 64 bits"},
      {"{'descr': '<f8' 'fortran_order': False, 'shape': (3,)}", "expected ',' or '}' after the value of 'descr'"},
      {"{descr: '<f8', 'fortran_order': False, 'shape': (3,)}", "expected a quoted string for a key, found 'd'"},
      {"{'descr': '<f\\x38', 'fortran_order': False, 'shape': (3,)}", "unterminated string (or one with an escape)"},
      {"{'descr': '<f8", "unterminated string"},
      {"[('descr', '<f8')]", "expected '{' at the start of the header, found '['"},
      {"{'descr': '<f8', 'fortran_order': False, 'shape': (3,)} 7", "unexpected '7' after the closing '}'"},
      {"{'descr': '<f8', 'fortran_order': False, 'shape': (3,)", "expected ',' or '}' after the value of 'shape', "
                                                                 "found the end of the header"},
      {std::string("{'descr': '<f8', 'fortran_order': False, 'shape': (3,)}\0", 57), "unexpected '?' after"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.dict);
    const std::string message = errorOf(npyFile(1, c.dict, data));
    EXPECT_EQ(message.rfind(kFile + ": ", 0), 0u) << message;
    EXPECT_NE(message.find(c.what), std::string::npos) << "expected '" << c.what << "' in '" << message << "'";
  }
  // Syntax errors name the byte: here the '0', 10 bytes of preamble before the dict.
  const std::string dict = "{'descr': '<f8', 'fortran_order': 0, 'shape': (3,)}";
  expectError(npyFile(1, dict, data), "byte " + std::to_string(10 + dict.find('0')), "header: 'fortran_order'");
}

TEST(Npy, RefusesUnsupportedDtypesByName) {
  for (const char* descr : {"<i4", "<i8", "|u1", "|b1", "<c16", "|O", "<f2", "<f16", "|f8", "=f8", "f8", "<U4"}) {
    EXPECT_EQ(errorOf(npyFile(1, dictOf(descr, "(3,)"), encoded(kF8Bits, false))),
              "test.npy: header: dtype '" + std::string(descr) + "' is not supported (need float64 or float32)");
  }
  const std::string structured = "{'descr': [('x', '<f8')], 'fortran_order': False, 'shape': (3,)}";
  expectError(npyFile(1, structured, encoded(kF8Bits, false)), "byte " + std::to_string(10 + structured.find('[')),
              "header: 'descr' is a structured dtype, which is not supported");
}

TEST(Npy, RefusesShapesOtherThan1DOr2D) {
  const std::string one = encoded<uint64_t>({0}, false);
  expectError(npyFile(1, dictOf("<f8", "()"), one), "header", "shape () is that of a scalar");
  expectError(npyFile(1, dictOf("<f8", "(1, 1, 1)"), one), "header", "shape (1, 1, 1) has 3 dimensions (need 1 or 2)");
  expectError(npyFile(1, dictOf("<f8", "(1, 1, 1, 1)"), one), "header", "has 4 dimensions");
  expectError(npyFile(1, dictOf("<f8", "(-1,)"), one), "header", "shape (-1,) has a negative dimension");
  expectError(npyFile(1, dictOf("<f8", "(-1, -1)"), one), "header", "shape (-1, -1) has a negative dimension");
}

// parseNpy fails on a file of `dict` then `data`, naming the byte where the data starts.
void expectDataError(const std::string& dict, const std::string& data, const std::string& what) {
  const std::string file = npyFile(1, dict, data);
  expectError(file, "byte " + std::to_string(file.size() - data.size()), what);
}

TEST(Npy, RefusesDataOfTheWrongSize) {
  const std::string six = encoded(kF8Bits, false) + encoded(kF8Bits, false);
  expectDataError(dictOf("<f8", "(3, 2)"), six.substr(0, 40),
                  "expected 48 bytes of data for shape (3, 2) of '<f8', found 40 (truncated file)");
  expectDataError(dictOf("<f8", "(3, 2)"), six + "\x01",
                  "expected 48 bytes of data for shape (3, 2) of '<f8', found 49 (trailing bytes)");
  expectDataError(dictOf("<f4", "(2,)"), six.substr(0, 16),
                  "expected 8 bytes of data for shape (2,) of '<f4', found 16 (trailing bytes)");
  expectDataError(dictOf("<f8", "(0, 3)"), six.substr(0, 8),
                  "expected 0 bytes of data for shape (0, 3) of '<f8', found 8");
}

// Shapes that would need terabytes fail on their size, before anything is allocated (an
// allocation would throw std::bad_alloc, which errorOf does not catch).
TEST(Npy, AbsurdShapesFailFast) {
  const std::string one = encoded<uint64_t>({0}, false);
  const std::string huge = std::to_string(int64_t{1} << 40);
  expectError(npyFile(1, dictOf("<f8", "(" + huge + ", " + huge + ")"), one), "header",
              "shape (" + huge + ", " + huge + ") of '<f8' is too large: its byte count overflows size_t");
  expectError(npyFile(1, dictOf("<f8", "(9223372036854775807, 2)"), one), "header", "overflows size_t");
  expectError(npyFile(1, dictOf("<f4", "(4611686018427387904,)"), one), "header", "overflows size_t");
  expectDataError(dictOf("<f8", "(" + huge + ",)"), one,
                  "expected " + std::to_string(uint64_t{1} << 43) + " bytes of data");
}

} // namespace
} // namespace quiver
