#include "formats/model/qvr_writer.h"

#include <algorithm>
#include <array>
#include <cstring>
#include <stdexcept>
#include <type_traits>

#include "formats/atomic_file.h"
#include "formats/model/fnv1a.h"

namespace quiver {

namespace {

using namespace qvr;

void storeLE(unsigned char* p, uint64_t v, size_t bytes) {
  for (size_t i = 0; i < bytes; ++i) p[i] = static_cast<unsigned char>(v >> (8 * i));
}

void storeF64(unsigned char* p, double v) {
  uint64_t bits;
  std::memcpy(&bits, &v, sizeof bits);
  storeLE(p, bits, 8);
}

struct Piece {
  SectionType type;
  const void* data;
  size_t size;
  uint32_t flags = 0;
};

template <class T>
Piece piece(SectionType type, const std::vector<T>& values, uint32_t flags = 0) {
  return {type, values.data(), values.size() * sizeof(T), flags};
}

// Little-endian hosts only, as the writer's memcpy of float arrays already assumes.
void append(std::vector<unsigned char>& out, const void* data, size_t bytes) {
  const auto* p = static_cast<const unsigned char*>(data);
  out.insert(out.end(), p, p + bytes);
}

size_t alignUp(size_t at) { return (at + kSectionAlignment - 1) / kSectionAlignment * kSectionAlignment; }

} // namespace

std::vector<double> energyCoefficientsFromGram(const double* gram, int64_t ld, int r) {
  const auto g = [&](int64_t i, int64_t j) { return gram[j * ld + i]; };  // i <= j
  const int64_t c2 = monomialCount2(r), c3 = monomialCount3(r), c4 = monomialCount4(r);
  std::vector<double> out(c2 + c3 + c4, 0.0);
  double* d2 = out.data();
  double* d3 = d2 + c2;
  double* d4 = d3 + c3;
  std::vector<std::array<int, 2>> pair;
  for (int j = 0; j < r; ++j)
    for (int k = j; k < r; ++k) pair.push_back({j, k});
  const int P = static_cast<int>(pair.size());
  for (int i = 0; i < r; ++i)
    for (int j = i; j < r; ++j) d2[monomialIndex2(r, i, j)] += (i == j ? 1.0 : 2.0) * g(i, j);
  for (int i = 0; i < r; ++i)
    for (int p = 0; p < P; ++p) {
      std::array<int, 3> m{i, pair[p][0], pair[p][1]};
      std::sort(m.begin(), m.end());
      d3[monomialIndex3(r, m[0], m[1], m[2])] += 2.0 * g(i, r + p);
    }
  for (int p = 0; p < P; ++p)
    for (int s = p; s < P; ++s) {
      std::array<int, 4> m{pair[p][0], pair[p][1], pair[s][0], pair[s][1]};
      std::sort(m.begin(), m.end());
      d4[monomialIndex4(r, m[0], m[1], m[2], m[3])] += (p == s ? 1.0 : 2.0) * g(r + p, r + s);
    }
  return out;
}

std::string formatModel(const ModelContents& c) {
  unsigned char info[kModelInfoSize] = {};
  visitModelInfoFields(c.info, [&info](size_t at, const auto& field) {
    if constexpr (std::is_same_v<std::decay_t<decltype(field)>, uint32_t>)
      storeLE(info + at, field, 4);
    else
      storeF64(info + at, field);
  });
  std::vector<float> basis32;
  if (c.info.basisPrecision == 32) {
    basis32.resize(c.basis.size());
    std::transform(c.basis.begin(), c.basis.end(), basis32.begin(), [](double v) { return static_cast<float>(v); });
  }
  std::vector<Piece> pieces = {{kModelInfo, info, sizeof info},
                               piece(kEnergyCoefficients, c.energy),
                               c.info.basisPrecision == 32 ? piece(kBasis, basis32) : piece(kBasis, c.basis),
                               piece(kRestPositions, c.restPositions),
                               piece(kSurfaceTriangles, c.triangles),
                               piece(kVertexMap, c.vertexMap),
                               piece(kGravityProjection, c.gravity),
                               piece(kEigenvalues, c.eigenvalues)};
  if (!c.tets.empty()) pieces.push_back(piece(kTets, c.tets));
  if (!c.rotations.empty()) pieces.push_back(piece(kModalRotations, c.rotations, kOptionalSection));
  if (!c.rigidBody.empty()) pieces.push_back(piece(kRigidBody, c.rigidBody, kOptionalSection));
  std::vector<unsigned char> render;
  if (!c.render.positions.empty()) {
    const ModelContents::RenderMesh& m = c.render;
    const uint32_t header[4] = {static_cast<uint32_t>(m.positions.size() / 3), static_cast<uint32_t>(m.triangles.size() / 3),
                                (m.normals.empty() ? 0 : kRenderNormals) | (m.uvs.empty() ? 0 : kRenderUVs), 0};
    for (uint32_t word : header) append(render, &word, 4);
    append(render, m.positions.data(), 4 * m.positions.size());
    append(render, m.triangles.data(), 4 * m.triangles.size());
    append(render, m.tets.data(), 4 * m.tets.size());
    append(render, m.weights.data(), 4 * m.weights.size());
    append(render, m.normals.data(), 4 * m.normals.size());
    append(render, m.uvs.data(), 4 * m.uvs.size());
    append(render, m.basis.data(), 4 * m.basis.size());
    pieces.push_back({kRenderMesh, render.data(), render.size(), kOptionalSection});
  }
  std::vector<unsigned char> fidelity;
  if (!c.fidelityCases.empty() || !c.fidelityFrequencyErrors.empty()) {
    fidelity.assign(8 + c.fidelityCases.size() * kFidelityRecordSize + 8 * c.fidelityFrequencyErrors.size(), 0);
    const uint32_t counts[2] = {static_cast<uint32_t>(c.fidelityCases.size()),
                                static_cast<uint32_t>(c.fidelityFrequencyErrors.size())};
    std::memcpy(fidelity.data(), counts, 8);
    for (size_t i = 0; i < c.fidelityCases.size(); ++i) {
      unsigned char* record = fidelity.data() + 8 + i * kFidelityRecordSize;
      const auto& fc = c.fidelityCases[i];
      if (fc.name.size() >= kFidelityNameSize)
        throw std::runtime_error("fidelity case name '" + fc.name + "' is longer than " +
                                 std::to_string(kFidelityNameSize - 1) + " characters");
      std::memcpy(record, fc.name.data(), fc.name.size());
      std::memcpy(record + kFidelityNameSize, &fc.error, 8);
      std::memcpy(record + kFidelityNameSize + 8, &fc.largestDisplacement, 8);
    }
    std::memcpy(fidelity.data() + 8 + c.fidelityCases.size() * kFidelityRecordSize, c.fidelityFrequencyErrors.data(),
                8 * c.fidelityFrequencyErrors.size());
    pieces.push_back(piece(kFidelity, fidelity, kOptionalSection));
  }

  const size_t tableSize = pieces.size() * kSectionEntrySize;
  std::vector<size_t> offsets;
  size_t end = kHeaderSize + tableSize;
  for (const Piece& p : pieces) {
    offsets.push_back(alignUp(end));
    end = offsets.back() + p.size;
  }
  std::string bytes(end, '\0');
  unsigned char* out = reinterpret_cast<unsigned char*>(bytes.data());
  for (size_t i = 0; i < pieces.size(); ++i) {
    const Piece& p = pieces[i];
    if (p.size > 0) std::memcpy(out + offsets[i], p.data, p.size);
    unsigned char* entry = out + kHeaderSize + i * kSectionEntrySize;
    storeLE(entry + kTypeAt, p.type, 4);
    storeLE(entry + kFlagsAt, p.flags, 4);
    storeLE(entry + kOffsetAt, offsets[i], 8);
    storeLE(entry + kSizeAt, p.size, 8);
    storeLE(entry + kChecksumAt, fnv1a64(p.data, p.size), 8);
  }
  std::memcpy(out, kMagic, sizeof kMagic);
  storeLE(out + kMajorAt, kVersionMajor, 2);
  storeLE(out + kMinorAt, kVersionMinor, 2);
  std::memcpy(out + kEndianTagAt, kEndianTag, sizeof kEndianTag);
  storeLE(out + kHeaderSizeAt, kHeaderSize, 4);
  storeLE(out + kSectionCountAt, pieces.size(), 4);
  storeLE(out + kTableOffsetAt, kHeaderSize, 8);
  storeLE(out + kFileSizeAt, bytes.size(), 8);
  storeLE(out + kTableChecksumAt, fnv1a64(out + kHeaderSize, tableSize), 8);
  storeLE(out + kHeaderChecksumAt, fnv1a64(out, kHeaderChecksumAt), 8);

  // The array bytes above were copied in this host's byte order; parseModel refuses big-endian
  // hosts, so this check also keeps such a host from writing a wrong file.
  ModelView view;
  std::string error;
  if (!parseModel(bytes.data(), bytes.size(), view, error))
    throw std::runtime_error("cannot write a .qvr model: its contents are inconsistent: " + error);
  return bytes;
}

void writeModelFile(const std::string& path, const ModelContents& contents) {
  writeFileAtomically(path, formatModel(contents));
}

ModelContents copyModel(const ModelView& view) {
  const ModelInfo& info = view.info;
  const size_t r = info.r, n = info.vertexCount, basisSize = 3 * n * r;
  ModelContents c;
  c.info = info;
  c.energy.assign(view.energy, view.energy + energyCoefficientCount(r));
  if (view.basis32)
    c.basis.assign(view.basis32, view.basis32 + basisSize);
  else
    c.basis.assign(view.basis64, view.basis64 + basisSize);
  c.restPositions.assign(view.restPositions, view.restPositions + 3 * n);
  c.triangles.assign(view.triangles, view.triangles + size_t{3} * info.triangleCount);
  c.vertexMap.assign(view.vertexMap, view.vertexMap + n);
  c.gravity.assign(view.gravity, view.gravity + 3 * r);
  c.eigenvalues.assign(view.eigenvalues, view.eigenvalues + info.eigenvalueCount);
  if (view.tets) c.tets.assign(view.tets, view.tets + size_t{4} * info.tetCount);
  if (view.rotations) c.rotations.assign(view.rotations, view.rotations + size_t{3} * info.vertexCount * info.r);
  for (uint32_t i = 0; i < view.fidelityCaseCount; ++i) {
    const unsigned char* record = view.fidelityCases + i * kFidelityRecordSize;
    ModelContents::FidelityCase fc{reinterpret_cast<const char*>(record), 0, 0};
    std::memcpy(&fc.error, record + kFidelityNameSize, 8);
    std::memcpy(&fc.largestDisplacement, record + kFidelityNameSize + 8, 8);
    c.fidelityCases.push_back(fc);
  }
  c.fidelityFrequencyErrors.assign(view.fidelityFrequencyErrors, view.fidelityFrequencyErrors + view.fidelityFrequencyCount);
  if (view.rigidBody) c.rigidBody.assign(view.rigidBody, view.rigidBody + rigidBodySize(r));
  const size_t V = view.renderVertexCount;
  if (V) {
    ModelContents::RenderMesh& m = c.render;
    m.positions.assign(view.renderPositions, view.renderPositions + 3 * V);
    m.triangles.assign(view.renderTriangles, view.renderTriangles + size_t{3} * view.renderTriangleCount);
    m.tets.assign(view.renderTets, view.renderTets + V);
    m.weights.assign(view.renderWeights, view.renderWeights + 4 * V);
    if (view.renderNormals) m.normals.assign(view.renderNormals, view.renderNormals + 3 * V);
    if (view.renderUVs) m.uvs.assign(view.renderUVs, view.renderUVs + 2 * V);
    m.basis.assign(view.renderBasis, view.renderBasis + 3 * V * r);
  }
  return c;
}

} // namespace quiver
