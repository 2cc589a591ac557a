#pragma once
// Helpers for the .qvr tests and fuzz target: synthetic models, .qvr files assembled field by
// field from QVR.md without the writer (independent little-endian encoding, explicit spec
// offsets), and recomputing a damaged file's checksums so that checks behind them can be reached.
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "formats/model/fnv1a.h"
#include "formats/model/qvr.h"
#include "formats/model/qvr_writer.h"

namespace quiver::test {

// ---- Little-endian encoding, written out independently of the code under test ----

inline void putLE(std::string& s, size_t at, uint64_t v, size_t bytes) {
  for (size_t i = 0; i < bytes; ++i) s[at + i] = static_cast<char>((v >> (8 * i)) & 0xff);
}
inline uint64_t getLE(const std::string& s, size_t at, size_t bytes) {
  uint64_t v = 0;
  for (size_t i = 0; i < bytes; ++i) v |= uint64_t{static_cast<unsigned char>(s[at + i])} << (8 * i);
  return v;
}
inline uint64_t bitsOf(double v) {
  uint64_t bits;
  std::memcpy(&bits, &v, 8);
  return bits;
}
inline void putF64(std::string& s, size_t at, double v) { putLE(s, at, bitsOf(v), 8); }

template <class T>
std::string arrayBytes(const std::vector<T>& values) {
  std::string s(values.size() * sizeof(T), '\0');
  for (size_t i = 0; i < values.size(); ++i) {
    uint64_t word = 0;
    std::memcpy(&word, &values[i], sizeof(T));  // the value's bits (a little-endian host is assumed)
    putLE(s, i * sizeof(T), word, sizeof(T));
  }
  return s;
}

// ---- Synthetic models ----

struct Counts {
  uint32_t r = 3, vertexCount = 5, tetCount = 2, triangleCount = 6, eigenvalueCount = 2;
  uint32_t basisPrecision = 32;
  bool withTets = true;
};

// Deterministic values in (-scale, scale), the first entries replaced by awkward ones (-0, a
// float32-subnormal, a float64-subnormal when `wide`).
inline std::vector<double> values(size_t count, uint64_t seed, double scale, bool wide) {
  std::vector<double> v(count);
  for (size_t i = 0; i < count; ++i) {
    seed = seed * 6364136223846793005ull + 1442695040888963407ull;
    v[i] = scale * (static_cast<double>(seed >> 11) / 4503599627370496.0 - 1.0);
  }
  const double awkward[] = {-0.0, 1e-45, wide ? 5e-324 : 0.5};
  for (size_t i = 0; i < count && i < 3; ++i) v[i] = awkward[i];
  return v;
}

// A valid model with the given counts: fileVertexCount is n + 2, vertex v maps to file vertex
// v + 2 (v < n - 1) and the last to 0; triangles and tets use consecutive vertices.
inline ModelContents syntheticModel(const Counts& k = {}) {
  ModelContents c;
  ModelInfo& info = c.info;
  info.r = k.r;
  info.vertexCount = k.vertexCount;
  info.tetCount = k.tetCount;
  info.triangleCount = k.triangleCount;
  info.fileVertexCount = k.vertexCount + 2;
  info.eigenvalueCount = k.eigenvalueCount;
  info.basisPrecision = k.basisPrecision;
  info.youngsModulus = 2.5e5;
  info.poissonRatio = 0.4;
  info.density = 1100;
  info.materialIsUniform = 0;
  info.totalMass = 3.25;
  info.rayleighAlpha = 0.1;
  info.rayleighBeta = 0.002;
  info.timeStep = 1.0 / 120;
  const size_t n = k.vertexCount, r = k.r;
  c.energy = values(energyCoefficientCount(r), 1, 1e7, true);
  c.basis = values(3 * n * r, 2, 3.0, k.basisPrecision == 64);
  c.restPositions = values(3 * n, 3, 2.0, true);
  for (size_t a = 0; a < 3; ++a) {
    info.bboxMin[a] = info.bboxMax[a] = c.restPositions[a];
    for (size_t v = 1; v < n; ++v) {
      info.bboxMin[a] = std::min(info.bboxMin[a], c.restPositions[3 * v + a]);
      info.bboxMax[a] = std::max(info.bboxMax[a], c.restPositions[3 * v + a]);
    }
  }
  for (uint32_t t = 0; t < k.triangleCount; ++t)
    for (uint32_t a = 0; a < 3; ++a) c.triangles.push_back((t + a) % k.vertexCount);
  for (uint32_t v = 0; v < k.vertexCount; ++v) c.vertexMap.push_back(v + 1 < k.vertexCount ? v + 2 : 0);
  c.gravity = values(3 * r, 4, 0.5, true);
  c.eigenvalues = values(k.eigenvalueCount, 5, 1e4, true);
  if (k.withTets)
    for (uint32_t t = 0; t < k.tetCount; ++t)
      for (uint32_t a = 0; a < 4; ++a) c.tets.push_back((t + a) % k.vertexCount);
  return c;
}

// ---- Files assembled from the spec ----

struct RawSection {
  uint32_t type = 0;
  uint32_t flags = 0;
  std::string bytes;
};

// MODEL_INFO's 192 bytes, field by field at the offsets listed in QVR.md.
inline std::string infoBytes(const ModelInfo& i) {
  std::string s(192, '\0');
  const uint32_t words[] = {i.r, i.vertexCount, i.tetCount, i.triangleCount, i.fileVertexCount,
                            i.eigenvalueCount, i.basisPrecision, i.coefficientLayout};
  for (size_t w = 0; w < 8; ++w) putLE(s, 4 * w, words[w], 4);
  putF64(s, 32, i.youngsModulus);
  putF64(s, 40, i.poissonRatio);
  putF64(s, 48, i.density);
  putLE(s, 56, i.materialIsUniform, 4);
  putF64(s, 64, i.totalMass);
  putF64(s, 72, i.rayleighAlpha);
  putF64(s, 80, i.rayleighBeta);
  for (size_t a = 0; a < 3; ++a) {
    putF64(s, 88 + 8 * a, i.bboxMin[a]);
    putF64(s, 112 + 8 * a, i.bboxMax[a]);
  }
  putF64(s, 136, i.timeStep);
  return s;
}

// The sections of `c` in type order, as QVR.md lays them out (the basis rounded to float32 when
// basisPrecision is 32).
inline std::vector<RawSection> sectionsOf(const ModelContents& c) {
  std::vector<float> basis32(c.basis.begin(), c.basis.end());
  std::vector<RawSection> s = {
      {1, 0, infoBytes(c.info)},
      {2, 0, arrayBytes(c.energy)},
      {3, 0, c.info.basisPrecision == 32 ? arrayBytes(basis32) : arrayBytes(c.basis)},
      {4, 0, arrayBytes(c.restPositions)},
      {5, 0, arrayBytes(c.triangles)},
      {6, 0, arrayBytes(c.vertexMap)},
      {7, 0, arrayBytes(c.gravity)},
      {8, 0, arrayBytes(c.eigenvalues)}};
  if (!c.tets.empty()) s.push_back({9, 0, arrayBytes(c.tets)});
  return s;
}

// Header fields a test may change; `headerExtra` makes a longer header (a later minor version).
struct HeaderFields {
  uint16_t major = 1, minor = 0;
  std::string headerExtra;
};

// Recomputes every checksum from the bytes as they are: each section whose range lies in the file,
// the section table and the header. Lets tests corrupt a field and still reach the check behind it.
inline void reseal(std::string& f) {
  const uint64_t headerSize = getLE(f, 16, 4), count = getLE(f, 20, 4), table = getLE(f, 24, 8);
  if (table <= f.size() && count <= (f.size() - table) / 32) {
    for (uint64_t e = table; e < table + 32 * count; e += 32) {
      const uint64_t offset = getLE(f, e + 8, 8), size = getLE(f, e + 16, 8);
      if (offset <= f.size() && size <= f.size() - offset) putLE(f, e + 24, fnv1a64(f.data() + offset, size), 8);
    }
    putLE(f, 40, fnv1a64(f.data() + table, 32 * count), 8);
  }
  if (headerSize >= 64 && headerSize <= f.size())
    putLE(f, 56, fnv1a64(f.data() + 64, headerSize - 64, fnv1a64(f.data(), 56)), 8);
}

// A whole file: the header, the table right after it, each section at the next multiple of 64.
inline std::string assemble(const std::vector<RawSection>& sections, const HeaderFields& h = {}) {
  const size_t headerSize = 64 + h.headerExtra.size(), table = headerSize;
  std::vector<size_t> offsets;
  size_t end = table + 32 * sections.size();
  for (const RawSection& s : sections) {
    offsets.push_back((end + 63) / 64 * 64);
    end = offsets.back() + s.bytes.size();
  }
  std::string f(end, '\0');
  f.replace(0, 8, "\x89QVR\r\n\x1a\n", 8);
  putLE(f, 8, h.major, 2);
  putLE(f, 10, h.minor, 2);
  putLE(f, 12, 0x01020304, 4);
  putLE(f, 16, headerSize, 4);
  putLE(f, 20, sections.size(), 4);
  putLE(f, 24, table, 8);
  putLE(f, 32, f.size(), 8);
  f.replace(64, h.headerExtra.size(), h.headerExtra);
  for (size_t i = 0; i < sections.size(); ++i) {
    const size_t e = table + 32 * i;
    putLE(f, e, sections[i].type, 4);
    putLE(f, e + 4, sections[i].flags, 4);
    putLE(f, e + 8, offsets[i], 8);
    putLE(f, e + 16, sections[i].bytes.size(), 8);
    f.replace(offsets[i], sections[i].bytes.size(), sections[i].bytes);
  }
  reseal(f);
  return f;
}

// ---- Parsing from an 8-byte aligned copy ----

// Holds an aligned copy of a file for as long as the views into it are used.
class AlignedFile {
public:
  explicit AlignedFile(const std::string& bytes, size_t shift = 0)
      : words_((bytes.size() + shift + 7) / 8 + 1), size_(bytes.size()), shift_(shift) {
    if (!bytes.empty()) std::memcpy(data(), bytes.data(), bytes.size());
  }
  unsigned char* data() { return reinterpret_cast<unsigned char*>(words_.data()) + shift_; }
  bool parse(ModelView& view, std::string& error) { return parseModel(data(), size_, view, error); }

private:
  std::vector<uint64_t> words_;
  size_t size_, shift_;
};

// The reader's error for `bytes`, or "" when they parse.
inline std::string parseError(const std::string& bytes) {
  AlignedFile file(bytes);
  ModelView view;
  std::string error;
  return file.parse(view, error) ? std::string() : error;
}

} // namespace quiver::test
