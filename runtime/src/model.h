#pragma once
// qv_model: a baked model in one block from the caller's allocator (and, for a free model, its
// surface as a triangle mesh in a second and its contact modes in a third, contact_modes.h),
// immutable once loaded and shared read-only by every instance of it.
#include <cstddef>

#include "contact_modes.h"
#include "quiver/quiver.h"
#include "reduced_polynomial.h"
#include "render_mesh.h"

struct qv_model {
  qv_allocator allocator;
  qv_model_info info;
  quiver::rt::ReducedPolynomial polynomial;
  const float* basis32;   // 3n x r row-major, or null
  const double* basis64;  // 3n x r row-major, or null
  const double* rest;
  const unsigned* triangles;
  const unsigned* vertexMap;
  const double* gravity;
  const double* eigenvalues;
  const double* rotations;      // 3n x r row-major modal rotations, or null
  const double* rigidBody;      // a free object's RIGID_BODY moments (rigid_frame.h), or null
  const double* restStiffness;  // K(0), r x r: linear modal dynamics and modal warping step with it
  double largestEigenvalue;     // of K(0) (omega_max^2): central differences' limit, qv_instance_stable_time_step
  // A free model's rest surface, which other instances touch in a world (contact.h); null when the
  // model is pinned or its surface is not closed.
  const qv_triangle_mesh* surfaceMesh;
  quiver::rt::RenderMesh render;  // no vertices when the model has none
  // A free model's surface vertices, the points that touch, spread evenly level by level
  // (contact_points.h); null when pinned.
  const int* contactVertices;
  const unsigned char* contactLevels;
  int contactCount;
  quiver::rt::ContactModes contactModes;  // how the deformation gives way at them (free models)

  double basisEntry(size_t row, size_t j) const {
    const size_t r = static_cast<size_t>(info.r);
    return basis32 ? static_cast<double>(basis32[row * r + j]) : basis64[row * r + j];
  }
  // Vertex v's linear displacement U_v q and, when `w` is not null, its modal rotation Psi_v q.
  void vertexLinear(int v, const double* q, double d[3], double w[3]) const;
};

namespace quiver::rt {

// Parses a .qvr image (8-byte aligned) and builds the model in one block from `allocator`. On a
// format error returns QV_ERROR_FORMAT with the reader's message in `message`.
qv_result loadModel(const void* data, size_t size, const qv_model_config& config, const qv_allocator& allocator,
                    qv_model** model, char* message, size_t messageSize);

void destroyModel(qv_model* model);

} // namespace quiver::rt
