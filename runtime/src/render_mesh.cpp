#include "render_mesh.h"

#include <cmath>
#include <cstring>

#include "instance.h"
#include "output.h"

namespace quiver::rt {

namespace {

template <class T>
T* mutableOf(const T* p) { return const_cast<T*>(p); }  // arrays of the block being filled

// 3 x 3 inverse, row-major; false when singular.
bool invert3(const double a[9], double out[9]) {
  out[0] = a[4] * a[8] - a[5] * a[7], out[1] = a[2] * a[7] - a[1] * a[8], out[2] = a[1] * a[5] - a[2] * a[4];
  out[3] = a[5] * a[6] - a[3] * a[8], out[4] = a[0] * a[8] - a[2] * a[6], out[5] = a[2] * a[3] - a[0] * a[5];
  out[6] = a[3] * a[7] - a[4] * a[6], out[7] = a[1] * a[6] - a[0] * a[7], out[8] = a[0] * a[4] - a[1] * a[3];
  const double det = a[0] * out[0] + a[1] * out[3] + a[2] * out[6];
  double scale = 0;  // the largest edge, cubed: a nearly flat tet would make float32 overflow
  for (int k = 0; k < 9; ++k) scale = std::fmax(scale, std::fabs(a[k]));
  if (!(std::fabs(det) > 1e-12 * scale * scale * scale)) return false;
  for (int k = 0; k < 9; ++k) out[k] /= det;
  return true;
}

} // namespace

void RenderMesh::carve(BlockCarver& c, const ModelView& view) {
  const size_t V = view.renderVertexCount, T = view.renderTriangleCount, m = view.info.tetCount;
  if (!V) return;
  vertexCount = static_cast<int>(V), triangleCount = static_cast<int>(T);
  rest = c.take<float>(3 * V);
  triangles = c.take<unsigned>(3 * T);
  tetOf = c.take<unsigned>(V);
  weights = c.take<float>(4 * V);
  normals = c.take<float>(3 * V);
  uvs = view.renderUVs ? c.take<float>(2 * V) : nullptr;
  tets = c.take<unsigned>(4 * m);
  restInverse = c.take<float>(9 * m);
}

void RenderMesh::fill(const ModelView& view, const double* x) {
  const size_t V = static_cast<size_t>(vertexCount), T = static_cast<size_t>(triangleCount), m = view.info.tetCount;
  if (!V) return;
  std::memcpy(mutableOf(rest), view.renderPositions, 12 * V);
  std::memcpy(mutableOf(triangles), view.renderTriangles, 12 * T);
  std::memcpy(mutableOf(tetOf), view.renderTets, 4 * V);
  std::memcpy(mutableOf(weights), view.renderWeights, 16 * V);
  if (uvs) std::memcpy(mutableOf(uvs), view.renderUVs, 8 * V);
  std::memcpy(mutableOf(tets), view.tets, 16 * m);
  float* n = mutableOf(normals);
  if (view.renderNormals) {
    std::memcpy(n, view.renderNormals, 12 * V);
  } else {  // area-weighted from the rest triangles
    areaWeightedNormals(rest, triangles, triangleCount, vertexCount, n);
  }
  for (size_t i = 0; i < V; ++i) {  // unit length; +z where a vertex has none
    float* ni = n + 3 * i;
    const float len = std::sqrt(ni[0] * ni[0] + ni[1] * ni[1] + ni[2] * ni[2]);
    for (int a = 0; a < 3; ++a) ni[a] = len > 0 ? ni[a] / len : (a == 2 ? 1.0f : 0.0f);
  }
  // Rest edge matrices [X1 - X0, X2 - X0, X3 - X0] (columns), inverted once: F = I + Du Dm^-1.
  float* inverse = mutableOf(restInverse);
  for (size_t t = 0; t < m; ++t) {
    const unsigned* v = tets + 4 * t;
    double D[9], Di[9];
    for (int a = 0; a < 3; ++a)
      for (int k = 0; k < 3; ++k) D[3 * a + k] = x[3 * v[k + 1] + a] - x[3 * v[0] + a];
    if (!invert3(D, Di)) std::memset(Di, 0, sizeof Di);  // a (nearly) flat tet: its vertices' normals stay as at rest
    for (int k = 0; k < 9; ++k) inverse[9 * t + k] = static_cast<float>(Di[k]);
  }
}

size_t RenderMesh::scratchBytes(int simVertexCount, int tetCount) const {
  return vertexCount ? sizeof(float) * (3 * static_cast<size_t>(simVertexCount) + 9 * static_cast<size_t>(tetCount)) : 0;
}

void renderOutput(const qv_instance& s, float* positions, float* normals, void* scratch) {
  const qv_model& model = *s.model;
  const RenderMesh& mesh = model.render;
  float* u = static_cast<float*>(scratch);  // the simulated vertices' displacements, 3n
  simulatedDisplacements(s, u);
  // cof(F) per tet, F = I + [u1 - u0, u2 - u0, u3 - u0] Dm^-1 (for the normals).
  float* cofactors = u + 3 * static_cast<size_t>(model.info.vertex_count);
  for (int t = 0; normals && t < model.info.tet_count; ++t) {
    const unsigned* v = mesh.tets + 4 * t;
    const float* Di = mesh.restInverse + 9 * t;
    float du[9], F[9];
    for (int a = 0; a < 3; ++a)
      for (int k = 0; k < 3; ++k) du[3 * a + k] = u[3 * v[k + 1] + a] - u[3 * v[0] + a];
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) F[3 * a + b] = (a == b) + du[3 * a] * Di[b] + du[3 * a + 1] * Di[3 + b] + du[3 * a + 2] * Di[6 + b];
    float* C = cofactors + 9 * t;
    C[0] = F[4] * F[8] - F[5] * F[7], C[1] = F[5] * F[6] - F[3] * F[8], C[2] = F[3] * F[7] - F[4] * F[6];
    C[3] = F[2] * F[7] - F[1] * F[8], C[4] = F[0] * F[8] - F[2] * F[6], C[5] = F[1] * F[6] - F[0] * F[7];
    C[6] = F[1] * F[5] - F[2] * F[4], C[7] = F[2] * F[3] - F[0] * F[5], C[8] = F[0] * F[4] - F[1] * F[3];
  }
  // One pass over the render vertices: each one's tet read once for its position and its normal.
  const size_t V = static_cast<size_t>(mesh.vertexCount);
  for (size_t i = 0; i < V; ++i) {
    const unsigned t = mesh.tetOf[i];
    const unsigned* v = mesh.tets + 4 * t;
    const float* w = mesh.weights + 4 * i;
    for (int a = 0; a < 3; ++a)
      positions[3 * i + a] = mesh.rest[3 * i + a] + w[0] * u[3 * v[0] + a] + w[1] * u[3 * v[1] + a] + w[2] * u[3 * v[2] + a] +
                             w[3] * u[3 * v[3] + a];
    if (!normals) continue;
    const float* C = cofactors + 9 * static_cast<size_t>(t);
    const float* n0 = mesh.normals + 3 * i;
    float n[3];
    for (int a = 0; a < 3; ++a) n[a] = C[3 * a] * n0[0] + C[3 * a + 1] * n0[1] + C[3 * a + 2] * n0[2];
    const float length2 = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
    const bool usable = length2 > 0 && std::isfinite(length2);
    const float scale = usable ? 1.0f / std::sqrt(length2) : 0.0f;
    for (int a = 0; a < 3; ++a) normals[3 * i + a] = usable ? n[a] * scale : n0[a];
  }
  intoWorld(s, positions, V);
  if (normals) directionsIntoWorld(s, normals, V);
}

} // namespace quiver::rt
