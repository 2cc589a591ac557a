#pragma once
// Writing .qvr runtime models (bake side: throws std::runtime_error). The format is specified in
// formats/model/QVR.md; the reader, which the runtime uses, is qvr.h.
#include <cstdint>
#include <string>
#include <vector>

#include "formats/model/qvr.h"

namespace quiver {

// Everything a .qvr file holds, owned. n = info.vertexCount, r = info.r; see ModelView.
struct ModelContents {
  ModelInfo info;
  std::vector<double> energy;         // energyCoefficientCount(r), in the order of qvr.h
  std::vector<double> basis;          // U, 3n x r, row-major; rounded to nearest float32 when info.basisPrecision is 32
  std::vector<double> restPositions;  // 3n
  std::vector<uint32_t> triangles;    // 3 x info.triangleCount, counter-clockwise seen from outside
  std::vector<uint32_t> vertexMap;    // n, each below info.fileVertexCount
  std::vector<double> gravity;        // 3 x r, row a = U^T M e_a
  std::vector<double> eigenvalues;    // info.eigenvalueCount
  std::vector<uint32_t> tets;         // 4 x info.tetCount, or empty to leave the TETS section out
  std::vector<double> rotations;      // 3n x r modal rotations (see ModelView), or empty to leave them out
  // The bake's fidelity report (see ModelView), or no cases and no frequencies to leave it out.
  struct FidelityCase {
    std::string name;                 // printable ASCII, shorter than kFidelityNameSize
    double error, largestDisplacement;  // NaN: not measured
  };
  std::vector<FidelityCase> fidelityCases;
  std::vector<double> fidelityFrequencyErrors;
  std::vector<double> rigidBody;      // rigidBodySize(r) values (see ModelView), or empty to leave them out
  // A render mesh embedded in the tets (see ModelView; needs tets), or no vertices to leave it out.
  struct RenderMesh {
    std::vector<float> positions;      // 3V
    std::vector<uint32_t> triangles;   // 3T
    std::vector<uint32_t> tets;        // V
    std::vector<float> weights;        // 4V
    std::vector<float> normals, uvs;   // 3V and 2V, or empty
    std::vector<float> basis;          // 3V x r
  } render;
};

// The ENERGY_COEFFICIENTS of q^T A2 q + 2 q^T A3 z + z^T A4 z (z the products q_j q_k, j <= k, in
// order) from the upper triangle of the Gram matrix [A2 A3; A3^T A4] of the reduced energy
// (common/reduced_energy.h): column-major, leading dimension `ld`, r + r(r+1)/2 square.
std::vector<double> energyCoefficientsFromGram(const double* gram, int64_t ld, int r);

// The bytes of a version 1.0 .qvr file: the sections in type order, each at the next multiple of
// 64 bytes after the section table or the previous section, zero padding, checksums. The result is
// checked with parseModel: contents a reader would refuse (a size that disagrees with info, a
// non-finite value, an index out of range, ...) throw std::runtime_error with the reader's message.
std::string formatModel(const ModelContents& contents);

// formatModel(contents) written to `path` atomically (temporary file + rename).
void writeModelFile(const std::string& path, const ModelContents& contents);

// A copy of a parsed model; float32 basis entries widen to double exactly.
ModelContents copyModel(const ModelView& view);

} // namespace quiver
