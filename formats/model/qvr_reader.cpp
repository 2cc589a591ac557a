// The .qvr reader: validates every byte of an untrusted file before handing out pointers into it.
// Standard library only, no exceptions, no RTTI (the runtime compiles this file into itself).
// Arithmetic on file values is done in uint64_t and ordered so that it cannot overflow.
#include "formats/model/qvr.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iterator>
#include <limits>
#include <string>
#include <type_traits>

#include "formats/model/fnv1a.h"

namespace quiver {

static_assert(std::numeric_limits<double>::is_iec559 && sizeof(double) == 8, "float64 must be IEEE binary64");
static_assert(std::numeric_limits<float>::is_iec559 && sizeof(float) == 4, "float32 must be IEEE binary32");

std::string qvr::sectionName(uint32_t type) {
  static const char* const kNames[] = {"", "MODEL_INFO", "ENERGY_COEFFICIENTS", "BASIS", "REST_POSITIONS",
                                       "SURFACE_TRIANGLES", "VERTEX_MAP", "GRAVITY_PROJECTION", "EIGENVALUES", "TETS",
                                       "MODAL_ROTATIONS", "FIDELITY", "RIGID_BODY", "RENDER_MESH"};
  static_assert(std::size(kNames) == kLastKnownType + 1, "one name for every known section type");
  return type >= 1 && type <= kLastKnownType ? kNames[type] : "section type " + std::to_string(type);
}

namespace {

using namespace qvr;

bool known(uint32_t type) { return type >= 1 && type <= kLastKnownType; }

// Little-endian loads that work on any host.
uint64_t loadLE(const unsigned char* p, size_t bytes) {
  uint64_t v = 0;
  for (size_t i = bytes; i-- > 0;) v = (v << 8) | p[i];
  return v;
}
uint16_t load16(const unsigned char* p) { return static_cast<uint16_t>(loadLE(p, 2)); }
uint32_t load32(const unsigned char* p) { return static_cast<uint32_t>(loadLE(p, 4)); }
uint64_t load64(const unsigned char* p) { return loadLE(p, 8); }
double loadF64(const unsigned char* p) {
  const uint64_t bits = load64(p);
  double v;
  std::memcpy(&v, &bits, sizeof v);
  return v;
}

// Finiteness from the exponent bits, which -ffast-math cannot optimise away.
bool finite64(uint64_t bits) { return (bits & 0x7ff0000000000000ull) != 0x7ff0000000000000ull; }
bool finite32(uint32_t bits) { return (bits & 0x7f800000u) != 0x7f800000u; }
bool finite(double v) {
  uint64_t bits;
  std::memcpy(&bits, &v, sizeof bits);
  return finite64(bits);
}

bool hostIsLittleEndian() {
  const uint32_t one = 1;
  unsigned char first;
  std::memcpy(&first, &one, 1);
  return first == 1;
}

std::string hex(uint64_t v) {
  char text[24];
  std::snprintf(text, sizeof text, "0x%016llx", static_cast<unsigned long long>(v));
  return text;
}

// The shortest of 15 to 17 significant digits that reads back as `v`.
std::string number(double v) {
  char text[32];
  for (int digits = 15; digits <= 17; ++digits) {
    std::snprintf(text, sizeof text, "%.*g", digits, v);
    if (std::strtod(text, nullptr) == v) break;
  }
  return text;
}

std::string checksumMismatch(uint64_t stored, uint64_t computed) {
  return "checksum mismatch (stored " + hex(stored) + ", computed " + hex(computed) + ")";
}

struct Section {  // a decoded section table entry
  uint32_t type = 0, flags = 0;
  uint64_t offset = 0, size = 0, checksum = 0;
};

class Parser {
public:
  Parser(const unsigned char* data, uint64_t size, std::string& error) : data_(data), size_(size), error_(error) {}

  bool parse(ModelView& out) {
    ModelView view;
    if (!checkBuffer() || !checkHeader() || !readTable() || !checkLayout() || !checkChecksums() ||
        !readInfo(view.info))
      return false;
    view.versionMinor = minor_;
    if (!checkContents(view)) return false;
    out = view;
    return true;
  }

private:
  bool fail(const std::string& message) {
    error_ = message;
    return false;
  }
  bool fail(const std::string& where, uint64_t at, const std::string& what) {
    return fail(where + " at byte " + std::to_string(at) + ": " + what);
  }
  bool failIn(const Section& s, const std::string& what) { return fail(sectionName(s.type), s.offset, what); }

  bool checkBuffer() {
    if (!hostIsLittleEndian()) return fail("this reader needs a little-endian host");
    if (reinterpret_cast<uintptr_t>(data_) % 8 != 0)
      return fail("the buffer at address " + hex(reinterpret_cast<uintptr_t>(data_)) +
                  " is not 8-byte aligned (load the file into memory from malloc, new or std::vector)");
    return true;
  }

  bool checkHeader() {
    const std::string header = "header";
    if (size_ < kHeaderSize)
      return fail(header, 0, "the file has " + std::to_string(size_) + " bytes, fewer than the " + std::to_string(kHeaderSize) + "-byte header");
    if (std::memcmp(data_, kMagic, 4) != 0) return fail(header, 0, "not a .qvr file (wrong magic bytes)");
    if (std::memcmp(data_, kMagic, sizeof kMagic) != 0)
      return fail(header, 4, "damaged magic bytes (line endings or ^Z changed: transferred in text mode?)");
    if (std::memcmp(data_ + kEndianTagAt, kEndianTag, sizeof kEndianTag) != 0)
      return fail(header, kEndianTagAt, "endianness tag is not the bytes 04 03 02 01 (not a little-endian .qvr file)");
    const uint16_t major = load16(data_ + kMajorAt);
    minor_ = load16(data_ + kMinorAt);
    if (major != kVersionMajor)
      return fail(header, kMajorAt, "version " + std::to_string(major) + "." + std::to_string(minor_) + " is " +
                                        (major > kVersionMajor ? "newer" : "older") + " than this reader (" +
                                        std::to_string(kVersionMajor) + ".x)");
    headerSize_ = load32(data_ + kHeaderSizeAt);
    if (headerSize_ < kHeaderSize || headerSize_ % 8 != 0 || headerSize_ > size_)
      return fail(header, kHeaderSizeAt, "header size " + std::to_string(headerSize_) +
                                             " is not a multiple of 8 from 64 to the file size " + std::to_string(size_));
    const uint64_t computed =
        fnv1a64(data_ + kHeaderSize, headerSize_ - kHeaderSize, fnv1a64(data_, kHeaderChecksumAt));
    const uint64_t stored = load64(data_ + kHeaderChecksumAt);
    if (stored != computed) return fail(header, kHeaderChecksumAt, checksumMismatch(stored, computed));
    const uint64_t fileSize = load64(data_ + kFileSizeAt);
    if (fileSize != size_)
      return fail(header, kFileSizeAt, "file size " + std::to_string(fileSize) + " does not match the " +
                                           std::to_string(size_) + " bytes given (truncated or extended file)");
    return true;
  }

  bool readTable() {
    count_ = load32(data_ + kSectionCountAt);
    if (count_ == 0 || count_ > kMaxSections)
      return fail("header", kSectionCountAt, "section count " + std::to_string(count_) + " is not in 1.." + std::to_string(kMaxSections));
    tableOffset_ = load64(data_ + kTableOffsetAt);
    const std::string table = "section table";
    if (tableOffset_ % 8 != 0) return fail(table, tableOffset_, "offset is not a multiple of 8");
    if (tableOffset_ < headerSize_)
      return fail(table, tableOffset_, "starts inside the " + std::to_string(headerSize_) + "-byte header");
    const uint64_t tableSize = uint64_t{count_} * kSectionEntrySize;
    if (tableOffset_ > size_ || tableSize > size_ - tableOffset_)
      return fail(table, tableOffset_, "runs past the end of the file (" + std::to_string(size_) + " bytes)");
    const unsigned char* entry = data_ + tableOffset_;
    const uint64_t computed = fnv1a64(entry, tableSize);
    const uint64_t stored = load64(data_ + kTableChecksumAt);
    if (stored != computed) return fail(table, tableOffset_, checksumMismatch(stored, computed));
    for (uint32_t i = 0; i < count_; ++i, entry += kSectionEntrySize) {
      Section& s = sections_[i];
      s.type = load32(entry + kTypeAt);
      s.flags = load32(entry + kFlagsAt);
      s.offset = load64(entry + kOffsetAt);
      s.size = load64(entry + kSizeAt);
      s.checksum = load64(entry + kChecksumAt);
      if (!checkSection(s)) return false;
    }
    for (uint32_t type = kModelInfo; type <= kLastKnownType; ++type)
      if (!byType_[type] && type != kTets && type != kModalRotations && type != kFidelity &&
          type != kRigidBody && type != kRenderMesh)
        return fail("missing required section " + sectionName(type));
    return true;
  }

  bool checkSection(Section& s) {
    if (s.offset % kSectionAlignment != 0) return failIn(s, "offset is not a multiple of " + std::to_string(kSectionAlignment));
    if (s.offset > size_ || s.size > size_ - s.offset)
      return failIn(s, std::to_string(s.size) + " bytes run past the end of the file (" + std::to_string(size_) +
                           " bytes)");
    for (const Section* other = sections_; other != &s; ++other)
      if (other->type == s.type)
        return failIn(s, "a second " + sectionName(s.type) + " section (the first is at byte " +
                             std::to_string(other->offset) + ")");
    if (!known(s.type) && !(s.flags & kOptionalSection))
      return failIn(s, "unknown section type without the optional flag (from a newer version?)");
    if (known(s.type)) byType_[s.type] = &s;
    return true;
  }

  // Every section's checksum, known type or not, once the layout is known to be sound.
  bool checkChecksums() {
    for (uint32_t i = 0; i < count_; ++i) {
      const Section& s = sections_[i];
      const uint64_t computed = fnv1a64(data_ + s.offset, static_cast<size_t>(s.size));
      if (computed != s.checksum) return failIn(s, checksumMismatch(s.checksum, computed));
    }
    return true;
  }

  bool zeroBytes(uint64_t from, uint64_t to) {
    for (uint64_t at = from; at < to; ++at)
      if (data_[at] != 0) return fail("padding", at, "not zero");
    return true;
  }

  // The header, the table and the sections follow each other in that order without overlapping, and
  // every byte between them (and after the last section) is zero.
  bool checkLayout() {
    const Section* order[kMaxSections];
    for (uint32_t i = 0; i < count_; ++i) order[i] = &sections_[i];
    std::sort(order, order + count_, [](const Section* a, const Section* b) {
      return a->offset != b->offset ? a->offset < b->offset : a->size < b->size;
    });
    if (!zeroBytes(headerSize_, tableOffset_)) return false;
    uint64_t end = tableOffset_ + uint64_t{count_} * kSectionEntrySize;
    std::string previous = "the section table";
    for (uint32_t i = 0; i < count_; ++i) {
      const Section& s = *order[i];
      if (s.offset < end) return failIn(s, "overlaps " + previous + " (which ends at byte " + std::to_string(end) + ")");
      if (!zeroBytes(end, s.offset)) return false;
      end = s.offset + s.size;
      previous = sectionName(s.type);
    }
    return zeroBytes(end, size_);
  }

  bool readInfo(ModelInfo& info) {
    const Section& s = *byType_[kModelInfo];
    if (s.size < kModelInfoSize)
      return failIn(s, "size " + std::to_string(s.size) + " is less than the " + std::to_string(kModelInfoSize) + " bytes of version 1.0");
    const unsigned char* p = data_ + s.offset;
    visitModelInfoFields(info, [p](size_t at, auto& field) {
      if constexpr (std::is_same_v<std::decay_t<decltype(field)>, uint32_t>)
        field = load32(p + at);
      else
        field = loadF64(p + at);
    });
    auto bad = [&](const std::string& what) { return failIn(s, what); };
    const std::string r = std::to_string(info.r), n = std::to_string(info.vertexCount);
    if (info.r < 1 || info.r > kMaxBasisSize) return bad("r = " + r + " is not in 1.." + std::to_string(kMaxBasisSize));
    if (info.vertexCount < 4) return bad("vertexCount " + n + " is less than 4");
    if (info.r > uint64_t{3} * info.vertexCount) return bad("r = " + r + " exceeds 3 x vertexCount " + n);
    if (info.tetCount < 1) return bad("tetCount is 0");
    if (info.triangleCount < 4) return bad("triangleCount " + std::to_string(info.triangleCount) + " is less than 4");
    if (info.fileVertexCount < info.vertexCount)
      return bad("fileVertexCount " + std::to_string(info.fileVertexCount) + " is less than vertexCount " + n);
    if (info.basisPrecision != 32 && info.basisPrecision != 64)
      return bad("basisPrecision " + std::to_string(info.basisPrecision) + " is not 32 or 64");
    if (info.coefficientLayout != kEnergyMonomials)
      return bad("coefficientLayout " + std::to_string(info.coefficientLayout) + " is not 1 (energy monomials)");
    if (info.materialIsUniform > 1)
      return bad("materialIsUniform " + std::to_string(info.materialIsUniform) + " is not 0 or 1");
    struct Range {
      const char* name;
      double value, low;
      bool lowIncluded;
      double high;
    };
    const double inf = std::numeric_limits<double>::infinity();
    const Range ranges[] = {{"youngsModulus", info.youngsModulus, 0, false, inf},
                            {"poissonRatio", info.poissonRatio, -1, false, 0.5},
                            {"density", info.density, 0, false, inf},
                            {"totalMass", info.totalMass, 0, false, inf},
                            {"rayleighAlpha", info.rayleighAlpha, 0, true, inf},
                            {"rayleighBeta", info.rayleighBeta, 0, true, inf},
                            {"timeStep", info.timeStep, kSmallestTimeStep, true, inf}};
    for (const Range& f : ranges)
      if (!finite(f.value) || !(f.lowIncluded ? f.value >= f.low : f.value > f.low) || !(f.value < f.high))
        return bad(std::string(f.name) + " " + number(f.value) + " is not finite and in " + (f.lowIncluded ? "[" : "(") +
                   number(f.low) + ", " + number(f.high) + ")");
    return true;
  }

  // Checks that section `type` holds `count` elements of `elementBytes`; `shape` describes the count.
  bool checkSize(const Section& s, uint64_t count, uint64_t elementBytes, const std::string& shape) {
    if (s.size == count * elementBytes) return true;
    return failIn(s, "size " + std::to_string(s.size) + " does not match " + shape + " x " +
                         std::to_string(elementBytes) + " bytes");
  }

  // A float64 (or float32) array section whose every value is finite.
  template <class Float>
  bool floats(SectionType type, uint64_t count, const std::string& shape, const Float*& out) {
    const Section& s = *byType_[type];
    if (!checkSize(s, count, sizeof(Float), shape)) return false;
    const unsigned char* p = data_ + s.offset;
    for (uint64_t i = 0; i < count; ++i) {
      const bool ok = sizeof(Float) == 8 ? finite64(load64(p + 8 * i)) : finite32(load32(p + 4 * i));
      if (!ok) return failIn(s, "value " + std::to_string(i) + " (byte " + std::to_string(s.offset + sizeof(Float) * i) +
                                    ") is not finite");
    }
    out = reinterpret_cast<const Float*>(p);
    return true;
  }

  // RIGID_BODY: finite values, the centre inside the bounding box, second moments symmetric with a
  // positive diagonal (a body with mass along every axis).
  bool rigidBody(ModelView& view) {
    const Section& s = *byType_[kRigidBody];
    const double* values = nullptr;
    if (!floats(kRigidBody, rigidBodySize(view.info.r), std::to_string(rigidBodySize(view.info.r)) + " values (r = " +
                                                             std::to_string(view.info.r) + ")", values))
      return false;
    double v[12];
    for (int i = 0; i < 12; ++i) v[i] = loadF64(data_ + s.offset + 8 * i);
    for (int a = 0; a < 3; ++a)
      if (!(v[a] >= view.info.bboxMin[a] && v[a] <= view.info.bboxMax[a]))
        return failIn(s, "the centre of mass lies outside the bounding box");
    for (int a = 0; a < 3; ++a) {
      if (!(v[3 + 4 * a] > 0)) return failIn(s, "second moment " + std::to_string(a) + std::to_string(a) + " is not positive");
      for (int b = 0; b < a; ++b)
        if (v[3 + 3 * a + b] != v[3 + 3 * b + a]) return failIn(s, "the second moments are not symmetric");
    }
    view.rigidBody = values;
    return true;
  }

  // RENDER_MESH: counts in range and the size they imply, triangles of distinct vertices in range,
  // tets in range of TETS (which it needs), weights of a point in or near its tet (each in [-1, 2],
  // summing to 1 within 1e-3), every value finite.
  bool renderMesh(const Section& s, ModelView& view) {
    if (s.size < kRenderHeaderSize) return failIn(s, "size " + std::to_string(s.size) + " is too small for its header");
    const unsigned char* p = data_ + s.offset;
    const uint32_t V = load32(p), T = load32(p + 4), flags = load32(p + 8);
    if (V < 3 || V > kMaxRenderCount) return failIn(s, "vertex count " + std::to_string(V) + " is not in 3.." + std::to_string(kMaxRenderCount));
    if (T < 1 || T > kMaxRenderCount) return failIn(s, "triangle count " + std::to_string(T) + " is not in 1.." + std::to_string(kMaxRenderCount));
    if (flags > (kRenderNormals | kRenderUVs) || load32(p + 12) != 0) return failIn(s, "unknown flags or a non-zero reserved word");
    const uint64_t expected = renderMeshSize(V, T, flags, view.info.r);
    if (s.size != expected)
      return failIn(s, "size " + std::to_string(s.size) + " is not the " + std::to_string(expected) + " bytes of " +
                           std::to_string(V) + " vertices and " + std::to_string(T) + " triangles");
    if (!view.tets) return failIn(s, "needs the TETS section, which the file does not have");
    uint64_t at = s.offset + kRenderHeaderSize;
    const auto floatsAt = [&](uint64_t count, const char* what, const float*& out) {
      for (uint64_t i = 0; i < count; ++i)
        if (!finite32(load32(data_ + at + 4 * i)))
          return failIn(s, std::string(what) + " value " + std::to_string(i) + " (byte " + std::to_string(at + 4 * i) + ") is not finite");
      out = reinterpret_cast<const float*>(data_ + at);
      at += 4 * count;
      return true;
    };
    const auto indicesAt = [&](uint64_t count, uint32_t group, uint32_t bound, const char* what, const uint32_t*& out) {
      for (uint64_t i = 0; i < count; ++i) {
        const uint32_t v = load32(data_ + at + 4 * i);
        if (v >= bound)
          return failIn(s, std::string(what) + " entry " + std::to_string(i) + " (byte " + std::to_string(at + 4 * i) + ") is " +
                               std::to_string(v) + ", not below " + std::to_string(bound));
        for (uint64_t k = i - i % group; k < i; ++k)
          if (load32(data_ + at + 4 * k) == v) return failIn(s, std::string(what) + " entry " + std::to_string(i) + " repeats a vertex of its triangle");
      }
      out = reinterpret_cast<const uint32_t*>(data_ + at);
      at += 4 * count;
      return true;
    };
    ModelView m = view;
    if (!floatsAt(3ull * V, "position", m.renderPositions) || !indicesAt(3ull * T, 3, V, "triangle", m.renderTriangles) ||
        !indicesAt(V, 1, view.info.tetCount, "tet", m.renderTets) || !floatsAt(4ull * V, "weight", m.renderWeights))
      return false;
    for (uint32_t i = 0; i < V; ++i) {
      const float* w = m.renderWeights + 4 * i;
      if (!(std::fabs(w[0] + w[1] + w[2] + w[3] - 1) <= 1e-3) || *std::min_element(w, w + 4) < -1 || *std::max_element(w, w + 4) > 2)
        return failIn(s, "vertex " + std::to_string(i) + "'s weights are not those of a point in or near its tet");
    }
    if ((flags & kRenderNormals) && !floatsAt(3ull * V, "normal", m.renderNormals)) return false;
    if ((flags & kRenderUVs) && !floatsAt(2ull * V, "UV", m.renderUVs)) return false;
    if (!floatsAt(3ull * V * view.info.r, "render basis", m.renderBasis)) return false;
    m.renderVertexCount = V, m.renderTriangleCount = T;
    view = m;
    return true;
  }

  // FIDELITY: counts in range, the size they imply, printable NUL-terminated names, values finite
  // (case values may also be NaN: not measured).
  bool fidelity(const Section& s, uint32_t eigenvalueCount, ModelView& view) {
    if (s.size < 8) return failIn(s, "size " + std::to_string(s.size) + " is too small for its two counts");
    const unsigned char* p = data_ + s.offset;
    const uint32_t cases = load32(p), frequencies = load32(p + 4);
    if (cases > kMaxFidelityCases)
      return failIn(s, "case count " + std::to_string(cases) + " is above " + std::to_string(kMaxFidelityCases));
    if (frequencies > eigenvalueCount)
      return failIn(s, "frequency count " + std::to_string(frequencies) + " is above the eigenvalue count " +
                           std::to_string(eigenvalueCount));
    const uint64_t expected = 8 + uint64_t{cases} * kFidelityRecordSize + 8 * uint64_t{frequencies};
    if (s.size != expected)
      return failIn(s, "size " + std::to_string(s.size) + " is not the " + std::to_string(expected) + " bytes of " +
                           std::to_string(cases) + " cases and " + std::to_string(frequencies) + " frequencies");
    for (uint32_t c = 0; c < cases; ++c) {
      const unsigned char* record = p + 8 + c * kFidelityRecordSize;
      const void* end = std::memchr(record, 0, kFidelityNameSize);
      if (!end) return failIn(s, "case " + std::to_string(c) + "'s name is not NUL-terminated");
      for (const unsigned char* ch = record; ch != end; ++ch)
        if (*ch < 0x20 || *ch > 0x7e) return failIn(s, "case " + std::to_string(c) + "'s name is not printable ASCII");
      for (int k = 0; k < 2; ++k) {
        const uint64_t bits = load64(record + kFidelityNameSize + 8 * k);
        if (!finite64(bits) && !((bits & 0x7ff0000000000000ull) == 0x7ff0000000000000ull && (bits & 0xfffffffffffffull)))
          return failIn(s, "case " + std::to_string(c) + " holds an infinite value");
      }
    }
    const unsigned char* errors = p + 8 + cases * kFidelityRecordSize;
    for (uint32_t i = 0; i < frequencies; ++i)
      if (!finite64(load64(errors + 8 * i))) return failIn(s, "frequency error " + std::to_string(i) + " is not finite");
    view.fidelityCaseCount = cases;
    view.fidelityFrequencyCount = frequencies;
    view.fidelityCases = p + 8;
    view.fidelityFrequencyErrors = reinterpret_cast<const double*>(errors);
    return true;
  }

  // An index array section: `groups` groups of `groupSize` distinct u32 indices below `bound`.
  bool indices(const Section& s, uint64_t groups, uint32_t groupSize, const std::string& shape, uint32_t bound,
               const char* boundName, const uint32_t*& out) {
    if (!checkSize(s, groups * groupSize, 4, shape)) return false;
    const unsigned char* p = data_ + s.offset;
    for (uint64_t g = 0; g < groups; ++g, p += 4 * groupSize)
      for (uint32_t a = 0; a < groupSize; ++a) {
        const uint32_t v = load32(p + 4 * a);
        auto bad = [&](const std::string& what) {
          return failIn(s, "entry " + std::to_string(g * groupSize + a) + " (byte " + std::to_string(p + 4 * a - data_) +
                               ") " + what);
        };
        if (v >= bound) return bad("is " + std::to_string(v) + ", not below " + boundName + " " + std::to_string(bound));
        for (uint32_t b = 0; b < a; ++b)
          if (load32(p + 4 * b) == v) return bad("repeats vertex " + std::to_string(v) + " of its group");
      }
    out = reinterpret_cast<const uint32_t*>(data_ + s.offset);
    return true;
  }

  // The bounding box in MODEL_INFO is exactly that of the rest positions.
  bool checkBoundingBox(const ModelView& view) {
    for (size_t a = 0; a < 3; ++a) {
      double low = view.restPositions[a], high = low;
      for (uint64_t v = 1; v < view.info.vertexCount; ++v) {
        low = std::min(low, view.restPositions[3 * v + a]);
        high = std::max(high, view.restPositions[3 * v + a]);
      }
      if (low != view.info.bboxMin[a] || high != view.info.bboxMax[a])
        return failIn(*byType_[kModelInfo], "bounding box along axis " + std::to_string(a) + " is [" +
                                                number(view.info.bboxMin[a]) + ", " + number(view.info.bboxMax[a]) +
                                                "], REST_POSITIONS span [" + number(low) + ", " + number(high) + "]");
    }
    return true;
  }

  bool checkContents(ModelView& view) {
    const ModelInfo& info = view.info;
    const uint64_t r = info.r, n = info.vertexCount;
    const std::string rText = std::to_string(r), vertices = std::to_string(n) + " vertices";
    const bool ok =
        floats(kEnergyCoefficients, energyCoefficientCount(r),
               std::to_string(energyCoefficientCount(r)) + " coefficients (r = " + rText + ")", view.energy) &&
        (info.basisPrecision == 32 ? floats(kBasis, 3 * n * r, "3 x " + vertices + " x " + rText, view.basis32)
                                   : floats(kBasis, 3 * n * r, "3 x " + vertices + " x " + rText, view.basis64)) &&
        floats(kRestPositions, 3 * n, "3 x " + vertices, view.restPositions) && checkBoundingBox(view) &&
        indices(*byType_[kSurfaceTriangles], info.triangleCount, 3,
                "3 x " + std::to_string(info.triangleCount) + " triangles", info.vertexCount, "vertexCount",
                view.triangles) &&
        indices(*byType_[kVertexMap], n, 1, vertices, info.fileVertexCount, "fileVertexCount", view.vertexMap) &&
        floats(kGravityProjection, 3 * r, "3 x " + rText, view.gravity) &&
        floats(kEigenvalues, info.eigenvalueCount, std::to_string(info.eigenvalueCount) + " eigenvalues",
               view.eigenvalues);
    if (!ok) return false;
    if (byType_[kModalRotations] &&
        !floats(kModalRotations, 3 * n * r, "3 x " + vertices + " x " + rText, view.rotations))
      return false;
    if (byType_[kFidelity] && !fidelity(*byType_[kFidelity], info.eigenvalueCount, view)) return false;
    if (byType_[kRigidBody] && !rigidBody(view)) return false;
    if (byType_[kTets] && !indices(*byType_[kTets], info.tetCount, 4, "4 x " + std::to_string(info.tetCount) + " tets",
                                   info.vertexCount, "vertexCount", view.tets))
      return false;
    return !byType_[kRenderMesh] || renderMesh(*byType_[kRenderMesh], view);
  }

  const unsigned char* data_;
  uint64_t size_;
  std::string& error_;
  uint16_t minor_ = 0;
  uint64_t headerSize_ = 0, tableOffset_ = 0;
  uint32_t count_ = 0;
  Section sections_[kMaxSections];
  const Section* byType_[kLastKnownType + 1] = {};
};

} // namespace

bool parseModel(const void* data, size_t size, ModelView& out, std::string& error) {
  return Parser(static_cast<const unsigned char*>(data), size, error).parse(out);
}

bool energyRisesAlongModes(const void* data, const ModelView& view, std::string& error) {
  const uint32_t r = view.info.r;
  const size_t quartic = monomialCount2(r) + monomialCount3(r);
  const size_t section = static_cast<size_t>(reinterpret_cast<const char*>(view.energy) - static_cast<const char*>(data));
  for (uint32_t i = 0; i < r; ++i) {
    const size_t at = quartic + monomialIndex4(r, i, i, i, i);
    if (view.energy[at] > 0) continue;
    const std::string mode = std::to_string(i);
    error = sectionName(kEnergyCoefficients) + " at byte " + std::to_string(section) + ": the coefficient of q" + mode +
            "^4 (value " + std::to_string(at) + ", byte " + std::to_string(section + 8 * at) + ") is " +
            number(view.energy[at]) + ", not positive: the energy falls without bound along mode " + mode +
            ", as no St.Venant-Kirchhoff energy does";
    return false;
  }
  return true;
}

} // namespace quiver
