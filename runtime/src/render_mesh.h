#pragma once
// A model's render mesh (RENDER_MESH in formats/model/QVR.md): triangles drawn in place of the tets'
// surface, each vertex carried by one tet with fixed weights. Each frame the simulated vertices'
// displacements (U q, warped under modal warping) are interpolated to the render vertices, and
// their rest normals turned by the cofactor of their tet's deformation gradient (normals of a
// deformed surface: n' ~ cof(F) n). All into the caller's buffers and scratch.
#include <cstddef>

#include "block_carver.h"
#include "formats/model/qvr.h"
#include "quiver/quiver.h"

struct qv_instance;

namespace quiver::rt {

struct RenderMesh {
  int vertexCount = 0, triangleCount = 0;
  const float* rest = nullptr;         // 3V
  const unsigned* triangles = nullptr; // 3T
  const unsigned* tetOf = nullptr;     // V
  const float* weights = nullptr;      // 4V
  const float* normals = nullptr;      // 3V at rest: as baked, or area-weighted from the triangles
  const float* uvs = nullptr;          // 2V or null
  const unsigned* tets = nullptr;      // 4 per tet of the model
  const float* restInverse = nullptr;  // 9 per tet: the inverse of its rest edge matrix, row-major

  // Takes its arrays from the model's block (none without a render mesh; null while measuring),
  // then fills them from the file.
  void carve(BlockCarver& c, const ModelView& view);
  void fill(const ModelView& view, const double* restPositions);
  size_t scratchBytes(int simVertexCount, int tetCount) const;
};

// The render mesh's positions (and, when `normals` is not null, normals) of instance `s`, 3 floats
// per render vertex, in the world in flight; `scratch` holds scratchBytes() (16-byte aligned).
void renderOutput(const qv_instance& s, float* positions, float* normals, void* scratch);

} // namespace quiver::rt
