// Loading a .qvr image into one block: measure, allocate once, place (block_carver.h).
#include "model.h"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <new>
#include <string>

#include "block_carver.h"
#include "contact_points.h"
#include "formats/model/qvr.h"
#include "triangle_mesh.h"

namespace quiver::rt {

namespace {

// K(0) into `stiffness` and its largest eigenvalue by power iteration (K(0) is symmetric, PSD).
// `scratch`: the polynomial's scratch plus two vectors of r.
double restStiffnessAndLargestEigenvalue(const qv_model& m, double* stiffness, double* scratch) {
  const int r = m.info.r;
  double* iterate = scratch;
  double* product = scratch + r;
  double* polynomialScratch = scratch + 2 * r;
  std::memset(iterate, 0, sizeof(double) * r);
  m.polynomial.evaluate(iterate, nullptr, nullptr, stiffness, polynomialScratch);
  for (int i = 0; i < r; ++i) iterate[i] = 1.0 + 0.01 * i;
  double lambda = 0;
  for (int it = 0; it < 200; ++it) {
    double norm = 0;
    for (int i = 0; i < r; ++i) {
      double y = 0;
      for (int j = 0; j < r; ++j) y += stiffness[i * r + j] * iterate[j];
      product[i] = y;
      norm += y * y;
    }
    norm = std::sqrt(norm);
    if (!(norm > 0)) return 0;
    double dot = 0;
    for (int i = 0; i < r; ++i) dot += product[i] * iterate[i];
    double previous = 0;
    for (int i = 0; i < r; ++i) previous += iterate[i] * iterate[i];
    lambda = dot / previous;
    for (int i = 0; i < r; ++i) iterate[i] = product[i] / norm;
  }
  return lambda;
}

// Lays the model out in `block` (null: only measures it) and, when placing, copies the view in
// and computes K(0) and the stable step. Returns the block's size.
size_t layOut(const ModelView& view, bool single, bool groups, const qv_allocator& allocator, char* block) {
  const ModelInfo& in = view.info;
  const size_t r = in.r, n = in.vertexCount;
  BlockCarver c(block);
  qv_model* m = c.take<qv_model>(1);
  char* polynomial = c.take<char>(ReducedPolynomial::storageBytes(in.r, single, groups));
  float* basis32 = view.basis32 ? c.take<float>(3 * n * r) : nullptr;
  double* basis64 = view.basis32 ? nullptr : c.take<double>(3 * n * r);
  double* rest = c.take<double>(3 * n);
  unsigned* triangles = c.take<unsigned>(3 * size_t(in.triangleCount));
  unsigned* vertexMap = c.take<unsigned>(n);
  double* gravity = c.take<double>(3 * r);
  double* eigenvalues = c.take<double>(in.eigenvalueCount);
  double* rotations = view.rotations ? c.take<double>(3 * n * r) : nullptr;
  double* rigidBody = view.rigidBody ? c.take<double>(qvr::rigidBodySize(r)) : nullptr;
  double* restStiffness = c.take<double>(r * r);
  int* contactVertices = view.rigidBody ? c.take<int>(n) : nullptr;
  unsigned char* contactLevels = view.rigidBody ? c.take<unsigned char>(n) : nullptr;
  RenderMesh render;
  render.carve(c, view);
  // Used once, while loading: a few kilobytes, so that a model stays one allocation.
  double* scratch = c.take<double>(2 * r + ReducedPolynomial::scratchSize(in.r));
  if (!block) return c.size();

  m = new (m) qv_model{};
  m->allocator = allocator;
  m->info = qv_model_info{static_cast<int>(in.r), static_cast<int>(in.vertexCount), static_cast<int>(in.tetCount),
                          static_cast<int>(in.triangleCount), static_cast<int>(in.fileVertexCount),
                          static_cast<int>(in.eigenvalueCount), static_cast<int>(in.basisPrecision),
                          static_cast<int>(in.materialIsUniform), view.rotations ? 1 : 0, view.rigidBody ? 1 : 0, in.youngsModulus, in.poissonRatio, in.density,
                          in.totalMass, in.rayleighAlpha, in.rayleighBeta, in.timeStep,
                          {in.bboxMin[0], in.bboxMin[1], in.bboxMin[2]}, {in.bboxMax[0], in.bboxMax[1], in.bboxMax[2]},
                          static_cast<int>(view.renderVertexCount), static_cast<int>(view.renderTriangleCount)};
  m->polynomial.build(in.r, view.energy, single, groups, polynomial);
  const auto copy = [](auto* target, const auto* source, size_t count) {
    if (count) std::memcpy(target, source, count * sizeof(*target));
    return target;
  };
  m->basis32 = view.basis32 ? copy(basis32, view.basis32, 3 * n * r) : nullptr;
  m->basis64 = view.basis32 ? nullptr : copy(basis64, view.basis64, 3 * n * r);
  m->rest = copy(rest, view.restPositions, 3 * n);
  m->triangles = copy(triangles, reinterpret_cast<const unsigned*>(view.triangles), 3 * size_t(in.triangleCount));
  m->vertexMap = copy(vertexMap, reinterpret_cast<const unsigned*>(view.vertexMap), n);
  m->gravity = copy(gravity, view.gravity, 3 * r);
  m->eigenvalues = copy(eigenvalues, view.eigenvalues, in.eigenvalueCount);
  m->rotations = view.rotations ? copy(rotations, view.rotations, 3 * n * r) : nullptr;
  m->rigidBody = view.rigidBody ? copy(rigidBody, view.rigidBody, qvr::rigidBodySize(r)) : nullptr;
  const double lambdaMax = restStiffnessAndLargestEigenvalue(*m, restStiffness, scratch);
  m->restStiffness = restStiffness;
  render.fill(view, rest);
  m->render = render;
  m->contactVertices = contactVertices;
  m->contactLevels = contactLevels;
  m->contactCount = view.rigidBody ? orderContactPoints(rest, int(n), m->triangles, int(in.triangleCount), allocator,
                                                        contactVertices, contactLevels) : 0;
  m->largestEigenvalue = lambdaMax > 0 ? lambdaMax : 0;
  return c.size();
}

void report(char* message, size_t size, const std::string& text) {
  if (message && size > 0) std::snprintf(message, size, "%s", text.c_str());
}

} // namespace

qv_result loadModel(const void* data, size_t size, const qv_model_config& config, const qv_allocator& allocator,
                    qv_model** out, char* message, size_t messageSize) {
  ModelView view;
  std::string error;
  if (!parseModel(data, size, view, error) || !energyRisesAlongModes(data, view, error)) {
    report(message, messageSize, error);
    return QV_ERROR_FORMAT;
  }
  const bool single = config.coefficient_precision == 32;
  // Past r = 64 the groups' rows would take more than 23 MB (quiver.h).
  const bool groups = config.group_layout == 1 || (config.group_layout == -1 && view.info.r <= 64);
  const size_t bytes = layOut(view, single, groups, allocator, nullptr);
  char* block = static_cast<char*>(allocator.allocate(bytes, 64, allocator.user));
  if (!block) return QV_ERROR_OUT_OF_MEMORY;
  layOut(view, single, groups, allocator, block);
  qv_model* model = reinterpret_cast<qv_model*>(block);
  if (model->contactCount < 0) {
    destroyModel(model);
    return QV_ERROR_OUT_OF_MEMORY;
  }
  if (model->rigidBody && model->info.triangle_count) {
    // Its surface for other instances to touch; an open surface only forgoes that.
    qv_triangle_mesh* surface = nullptr;
    static_assert(sizeof(unsigned) == sizeof(int), "triangles are passed as int");
    const qv_result built = createTriangleMesh(model->rest, model->info.vertex_count, reinterpret_cast<const int*>(model->triangles),
                                               model->info.triangle_count, allocator, &surface, nullptr, 0);
    if (built == QV_ERROR_OUT_OF_MEMORY) {
      destroyModel(model);
      return built;
    }
    model->surfaceMesh = surface;
  }
  if (model->contactCount > 0 && !buildContactModes(*model, allocator, model->contactModes)) {
    destroyModel(model);
    return QV_ERROR_OUT_OF_MEMORY;
  }
  *out = model;
  return QV_OK;
}

void destroyModel(qv_model* model) {
  const qv_allocator allocator = model->allocator;
  if (model->surfaceMesh) destroyTriangleMesh(const_cast<qv_triangle_mesh*>(model->surfaceMesh));
  destroyContactModes(model->contactModes, allocator);
  model->~qv_model();
  allocator.release(model, allocator.user);
}

} // namespace quiver::rt

void qv_model::vertexLinear(int v, const double* q, double d[3], double w[3]) const {
  const size_t r = static_cast<size_t>(info.r);
  for (int c = 0; c < 3; ++c) {
    const size_t row = 3 * static_cast<size_t>(v) + c;
    double du = 0, dw = 0;
    for (size_t j = 0; j < r; ++j) {
      du += basisEntry(row, j) * q[j];
      if (w) dw += rotations[row * r + j] * q[j];
    }
    d[c] = du;
    if (w) w[c] = dw;
  }
}
