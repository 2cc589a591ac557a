#include "output.h"

#include <cmath>
#include <cstring>

#include "quiver/modal_warping.h"

namespace quiver::rt {

namespace {

// Vertex v's displacement: U_v q, warped by its rotation under modal warping.
void vertexDisplacement(const qv_instance& s, int v, double u[3]) {
  if (s.config.elasticity != QV_ELASTICITY_MODAL_WARPING) {
    s.model->vertexLinear(v, s.q, u, nullptr);
    return;
  }
  double d[3], w[3];
  s.model->vertexLinear(v, s.q, d, w);
  warping::warpDisplacement(w, d, u);
}

} // namespace

// In flight, body positions (X + u) into the world: x + R (X + u - c).
void intoWorld(const qv_instance& s, float* p, size_t count) {
  if (!s.flying()) return;
  const double* c = s.model->rigidBody;
  for (size_t k = 0; k < count; ++k) {
    const double body[3] = {p[3 * k] - c[0], p[3 * k + 1] - c[1], p[3 * k + 2] - c[2]};
    double world[3];
    s.frame.toWorld(body, world);
    for (int a = 0; a < 3; ++a) p[3 * k + a] = static_cast<float>(world[a]);
  }
}

void directionsIntoWorld(const qv_instance& s, float* d, size_t count) {
  if (!s.flying()) return;
  for (size_t k = 0; k < count; ++k) {
    const double body[3] = {d[3 * k], d[3 * k + 1], d[3 * k + 2]};
    double world[3];
    s.frame.toWorldDirection(body, world);
    for (int a = 0; a < 3; ++a) d[3 * k + a] = static_cast<float>(world[a]);
  }
}

void simulatedDisplacements(const qv_instance& s, float* out) {
  if (s.config.elasticity != QV_ELASTICITY_MODAL_WARPING) {
    displacements(*s.model, s.q, out);
    return;
  }
  for (int v = 0; v < s.model->info.vertex_count; ++v) {
    double u[3];
    vertexDisplacement(s, v, u);
    for (int c = 0; c < 3; ++c) out[3 * v + c] = static_cast<float>(u[c]);
  }
}

void displacements(const qv_model& m, const double* q, float* out) {
  const size_t rows = 3 * static_cast<size_t>(m.info.vertex_count), r = m.info.r;
  for (size_t i = 0; i < rows; ++i) {
    double u = 0;
    if (m.basis32)
      for (size_t j = 0; j < r; ++j) u += static_cast<double>(m.basis32[i * r + j]) * q[j];
    else
      for (size_t j = 0; j < r; ++j) u += m.basis64[i * r + j] * q[j];
    out[i] = static_cast<float>(u);
  }
}

void positions(const qv_instance& s, float* out) {
  const qv_model& m = *s.model;
  simulatedDisplacements(s, out);
  for (size_t i = 0; i < 3 * static_cast<size_t>(m.info.vertex_count); ++i) out[i] = static_cast<float>(m.rest[i] + out[i]);
  intoWorld(s, out, static_cast<size_t>(m.info.vertex_count));
}

void positionsOf(const qv_instance& s, const int* vertices, int count, float* out) {
  for (int k = 0; k < count; ++k) {
    double u[3];
    vertexDisplacement(s, vertices[k], u);
    for (int c = 0; c < 3; ++c) out[3 * k + c] = static_cast<float>(s.model->rest[3 * vertices[k] + c] + u[c]);
  }
  intoWorld(s, out, static_cast<size_t>(count));
}

void areaWeightedNormals(const float* p, const unsigned* triangles, int triangleCount, int vertexCount, float* normals) {
  std::memset(normals, 0, sizeof(float) * 3 * static_cast<size_t>(vertexCount));
  for (int t = 0; t < triangleCount; ++t) {
    const unsigned* v = triangles + 3 * t;
    const float* a = p + 3 * v[0];
    const float* b = p + 3 * v[1];
    const float* c = p + 3 * v[2];
    const float e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    const float n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
    for (int k = 0; k < 3; ++k)
      for (int c2 = 0; c2 < 3; ++c2) normals[3 * v[k] + c2] += n[c2];  // area-weighted: |n| = 2 x area
  }
  for (int i = 0; i < vertexCount; ++i) {
    float* n = normals + 3 * i;
    const float len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (len > 0)
      for (int c = 0; c < 3; ++c) n[c] /= len;
  }
}

void surfaceNormals(const qv_model& m, const float* p, float* normals) {
  areaWeightedNormals(p, m.triangles, m.info.triangle_count, m.info.vertex_count, normals);
}

} // namespace quiver::rt
