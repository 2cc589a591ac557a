#pragma once
// The .qvr runtime model (format 1.0, specified in formats/model/QVR.md): constants, the monomial
// order of the energy coefficients, and the reader. Standard library only and exception-free, so
// that the runtime compiles qvr_reader.cpp into itself; the bake-side writer is qvr_writer.h.
#include <cstddef>
#include <cstdint>
#include <string>

namespace quiver {

namespace qvr {

constexpr unsigned char kMagic[8] = {0x89, 'Q', 'V', 'R', '\r', '\n', 0x1a, '\n'};
constexpr unsigned char kEndianTag[4] = {0x04, 0x03, 0x02, 0x01};  // u32 0x01020304, little-endian
constexpr uint16_t kVersionMajor = 1;
constexpr uint16_t kVersionMinor = 0;
constexpr size_t kHeaderSize = 64;         // of version 1.0; later minors may write more
constexpr size_t kSectionEntrySize = 32;
constexpr size_t kSectionAlignment = 64;   // every section offset is a multiple of this
constexpr uint32_t kMaxSections = 64;
constexpr size_t kModelInfoSize = 192;     // of version 1.0; later minors may append fields
constexpr uint32_t kMaxBasisSize = 256;    // r
constexpr uint32_t kOptionalSection = 1;   // section flag bit 0: readers that do not know the type skip it
constexpr uint32_t kEnergyMonomials = 1;   // ModelInfo::coefficientLayout

// Byte offsets of the header fields (bytes 0-7 are the magic, 48-55 are reserved).
constexpr size_t kMajorAt = 8, kMinorAt = 10, kEndianTagAt = 12, kHeaderSizeAt = 16, kSectionCountAt = 20,
                 kTableOffsetAt = 24, kFileSizeAt = 32, kTableChecksumAt = 40, kHeaderChecksumAt = 56;
// Byte offsets of the fields of a section table entry.
constexpr size_t kTypeAt = 0, kFlagsAt = 4, kOffsetAt = 8, kSizeAt = 16, kChecksumAt = 24;

enum SectionType : uint32_t {
  kModelInfo = 1,
  kEnergyCoefficients = 2,
  kBasis = 3,
  kRestPositions = 4,
  kSurfaceTriangles = 5,
  kVertexMap = 6,
  kGravityProjection = 7,
  kEigenvalues = 8,
  kTets = 9,             // optional: readers need not have it
  kModalRotations = 10,  // optional (written with the optional flag, so 1.0 readers skip it)
  kFidelity = 11,        // optional, likewise: the bake's fidelity report
  kRigidBody = 12,       // optional, likewise: a free object's mass moments (common/rigid_body.h)
  kRenderMesh = 13,      // optional, likewise: a render mesh embedded in the tets (needs TETS)
};
constexpr uint32_t kLastKnownType = kRenderMesh;
// RIGID_BODY: f64 centre of mass c (3), second moments S0 about c (3 x 3, row-major), first
// moments B (9 x r, row 3a + b) and second moments A of the basis (9 blocks of r x r, block
// 3a + b, row-major): rigidBodySize(r) values.
constexpr size_t rigidBodySize(uint64_t r) { return static_cast<size_t>(12 + 9 * r + 9 * r * r); }

// RENDER_MESH: a 16-byte header (u32 vertex count V, u32 triangle count T, u32 flags: bit 0 normals,
// bit 1 UVs; u32 zero), then f32 rest positions (3V), u32 triangles (3T), u32 each vertex's tet (V),
// f32 its weights on that tet's four vertices (4V), f32 normals (3V, with bit 0), f32 UVs (2V, with
// bit 1), f32 render basis rows W U (3V x r, row-major).
constexpr uint32_t kRenderNormals = 1, kRenderUVs = 2;
constexpr uint32_t kMaxRenderCount = 1u << 26;  // vertices or triangles
constexpr size_t kRenderHeaderSize = 16;
constexpr uint64_t renderMeshSize(uint64_t vertices, uint64_t triangles, uint32_t flags, uint64_t r) {
  return kRenderHeaderSize + 4 * (3 * vertices + 3 * triangles + vertices + 4 * vertices + 3 * vertices * r +
                                  (flags & kRenderNormals ? 3 * vertices : 0) + (flags & kRenderUVs ? 2 * vertices : 0));
}

// FIDELITY: u32 case count c (<= kMaxFidelityCases), u32 frequency count f (<= the eigenvalue
// count), c records of kFidelityRecordSize bytes (a NUL-padded ASCII name of kFidelityNameSize
// bytes, f64 displacement error, f64 largest displacement), then f f64 frequency errors.
constexpr uint32_t kMaxFidelityCases = 16;
constexpr size_t kFidelityNameSize = 24, kFidelityRecordSize = kFidelityNameSize + 16;

// "MODAL_ROTATIONS", ..., or "section type N" for a type this reader does not know: the one table
// of names, used by the reader's messages and by `quiver info`.
std::string sectionName(uint32_t type);

} // namespace qvr

// Energy monomials (coefficientLayout 1). The reduced elastic energy is
//   E(q) = sum_{i<=j} c_ij q_i q_j + sum_{i<=j<=k} c_ijk q_i q_j q_k + sum_{i<=j<=k<=l} c_ijkl q_i q_j q_k q_l
// over indices in [0, r). The coefficients are stored degree by degree, each degree's sorted index
// tuples in lexicographic order: (0,0), (0,1), ..., (0,r-1), (1,1), ..., (r-1,r-1).
// monomialCountD(r) is the number of degree-D monomials, C(r+D-1, D). Exact for r < 2^15.
constexpr size_t monomialCount2(uint64_t r) { return static_cast<size_t>(r * (r + 1) / 2); }
constexpr size_t monomialCount3(uint64_t r) { return static_cast<size_t>(r * (r + 1) * (r + 2) / 6); }
constexpr size_t monomialCount4(uint64_t r) { return static_cast<size_t>(r * (r + 1) * (r + 2) * (r + 3) / 24); }
constexpr size_t energyCoefficientCount(uint64_t r) { return monomialCount2(r) + monomialCount3(r) + monomialCount4(r); }

// Position of a monomial within its degree's block, for sorted indices i <= j <= k <= l < r. The
// tuples before it are those starting below i (all tuples over [0, r) minus those over [i, r)),
// then those starting with i, which are the shorter tuples over [i, r) shifted by i.
constexpr size_t monomialIndex2(uint32_t r, uint32_t i, uint32_t j) {
  return monomialCount2(r) - monomialCount2(r - i) + (j - i);
}
constexpr size_t monomialIndex3(uint32_t r, uint32_t i, uint32_t j, uint32_t k) {
  return monomialCount3(r) - monomialCount3(r - i) + monomialIndex2(r - i, j - i, k - i);
}
constexpr size_t monomialIndex4(uint32_t r, uint32_t i, uint32_t j, uint32_t k, uint32_t l) {
  return monomialCount4(r) - monomialCount4(r - i) + monomialIndex3(r - i, j - i, k - i, l - i);
}

// The MODEL_INFO section: counts, material and simulation defaults. Units are those of the baked
// input (SI: m, kg, s, Pa). A reader validates every field as noted.
struct ModelInfo {
  uint32_t r = 0;                                // basis size, 1..256 and at most 3 vertexCount
  uint32_t vertexCount = 0;                      // n, vertices of the simulated mesh, >= 4
  uint32_t tetCount = 0;                         // m, >= 1
  uint32_t triangleCount = 0;                    // surface triangles, >= 4
  uint32_t fileVertexCount = 0;                  // vertices in the input mesh file, >= n
  uint32_t eigenvalueCount = 0;                  // entries of EIGENVALUES, may be 0
  uint32_t basisPrecision = 32;                  // bits per BASIS entry: 32 or 64
  uint32_t coefficientLayout = qvr::kEnergyMonomials;  // 1, the only layout of version 1.0
  double youngsModulus = 1e6;                    // E, Pa, > 0 (volume-weighted mean if mixed)
  double poissonRatio = 0.45;                    // nu, in (-1, 0.5) (volume-weighted mean if mixed)
  double density = 1000.0;                       // rho, kg/m^3, > 0 (volume-weighted mean if mixed)
  uint32_t materialIsUniform = 1;                // 1: every tet has this material, 0: mixed
  double totalMass = 0;                          // kg, > 0
  double rayleighAlpha = 0;                      // default damping C = alpha I + beta K(q): 1/s, >= 0
  double rayleighBeta = 0;                       // s, >= 0
  double bboxMin[3] = {0, 0, 0};                 // componentwise min of REST_POSITIONS, exactly
  double bboxMax[3] = {0, 0, 0};                 // componentwise max of REST_POSITIONS, exactly
  double timeStep = 1.0 / 60.0;                  // suggested time step, s, >= kSmallestTimeStep
};

// The smallest time step a model suggests or an instance takes, s: far below any stable step of an
// explicit integrator on a real model, and 1 / h^2, which the implicit ones scale by, stays far from
// overflowing (at 1e-300 s it overflowed, and a state gone non-finite was blamed on the load).
constexpr double kSmallestTimeStep = 1e-12;

// MODEL_INFO's byte layout, the one place it is written down in code: calls visit(byteOffset, field)
// for every field. `Info` is ModelInfo or const ModelInfo. Bytes 60-63 and 144-191 are reserved.
template <class Info, class Visit>
void visitModelInfoFields(Info& info, Visit&& visit) {
  visit(0, info.r);
  visit(4, info.vertexCount);
  visit(8, info.tetCount);
  visit(12, info.triangleCount);
  visit(16, info.fileVertexCount);
  visit(20, info.eigenvalueCount);
  visit(24, info.basisPrecision);
  visit(28, info.coefficientLayout);
  visit(32, info.youngsModulus);
  visit(40, info.poissonRatio);
  visit(48, info.density);
  visit(56, info.materialIsUniform);
  visit(64, info.totalMass);
  visit(72, info.rayleighAlpha);
  visit(80, info.rayleighBeta);
  for (size_t a = 0; a < 3; ++a) visit(88 + 8 * a, info.bboxMin[a]);
  for (size_t a = 0; a < 3; ++a) visit(112 + 8 * a, info.bboxMax[a]);
  visit(136, info.timeStep);
}

// A validated model, pointing into the caller's buffer (nothing is copied: keep the buffer alive
// and unchanged while the view is used). n = vertexCount, r = info.r.
struct ModelView {
  ModelInfo info;
  uint16_t versionMinor = 0;                // of the file; fields of later minors are ignored
  const double* energy = nullptr;           // energyCoefficientCount(r) coefficients, see above
  const float* basis32 = nullptr;           // basisPrecision 32: U, 3n rows x r, row-major; else null
  const double* basis64 = nullptr;          // basisPrecision 64: the same in float64; else null
  const double* restPositions = nullptr;    // 3n: x, y, z of each vertex
  const uint32_t* triangles = nullptr;      // 3 triangleCount vertex indices, counter-clockwise seen from outside
  const uint32_t* vertexMap = nullptr;      // n: each vertex's index in the input mesh file
  const double* gravity = nullptr;          // 3 x r: row a is U^T M e_a (e_a: unit acceleration along axis a)
  const double* eigenvalues = nullptr;      // eigenvalueCount values
  const uint32_t* tets = nullptr;           // 4 tetCount vertex indices; null when the file has no TETS
  const double* rotations = nullptr;        // 3n x r, row-major: vertex v's small rotation w_v = Psi_v q (modal
                                            // warping, Choi & Ko 2005); null when the file has no MODAL_ROTATIONS
  // The bake's fidelity report (QVR.md, FIDELITY); counts zero when the file has none. Case i's
  // name is the NUL-terminated text at fidelityCases + i * kFidelityRecordSize, followed by its
  // displacement error and largest displacement as little-endian f64 (NaN: not measured).
  uint32_t fidelityCaseCount = 0, fidelityFrequencyCount = 0;
  const unsigned char* fidelityCases = nullptr;
  const double* fidelityFrequencyErrors = nullptr;
  const double* rigidBody = nullptr;        // rigidBodySize(r) values (see RIGID_BODY); null when the file has none
  // RENDER_MESH (see above): a render mesh whose vertex i moves as sum_k renderWeights[4i + k] times the
  // displacement of vertex k of tet renderTets[i]; counts zero when the file has none.
  uint32_t renderVertexCount = 0, renderTriangleCount = 0;
  const float* renderPositions = nullptr;     // 3V, at rest
  const uint32_t* renderTriangles = nullptr;  // 3T
  const uint32_t* renderTets = nullptr;       // V
  const float* renderWeights = nullptr;       // 4V
  const float* renderNormals = nullptr;       // 3V, or null
  const float* renderUVs = nullptr;           // 2V, or null
  const float* renderBasis = nullptr;         // 3V x r
};

// Validates the .qvr file held in `data` (the whole file, `size` bytes, 8-byte aligned as malloc,
// new and std::vector give) and on success fills `out` and returns true. On failure returns false
// with `error` naming the section or field, its byte offset and what is wrong; `out` is then
// left unchanged. Never throws (beyond std::bad_alloc while building a message); safe on any input.
bool parseModel(const void* data, size_t size, ModelView& out, std::string& error);

// Whether the energy of a model `view` parsed from `data` rises without bound along each mode's
// own axis: every c_iiii > 0, as in any St.Venant-Kirchhoff energy (mode i's Green strain grows as
// q_i^2). Else false, with `error` naming the coefficient, its byte offset and its value: the
// energy falls without bound, and no simulation of it can stay near rest. A necessary condition,
// cheap enough for every load (the runtime refuses such a model; its steps stay in a bounded box
// of q whatever the energy). Not part of parseModel, whose contract is the format's.
bool energyRisesAlongModes(const void* data, const ModelView& view, std::string& error);

} // namespace quiver
