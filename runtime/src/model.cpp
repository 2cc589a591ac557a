// qv_model: a baked model loaded from a .qvr image, in one block from the caller's allocator.
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <new>
#include <string>

#include "formats/model/qvr.h"
#include "quiver/quiver.h"
#include "block_carver.h"
#include "reduced_polynomial.h"

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
  const double* rotations;  // 3n x r row-major modal rotations, or null
};

namespace {

void* heapAllocate(size_t size, size_t alignment, void*) {
  void* p = nullptr;
  return posix_memalign(&p, alignment < sizeof(void*) ? sizeof(void*) : alignment, size) == 0 ? p : nullptr;
}
void heapRelease(void* p, void*) { std::free(p); }

void report(char* message, size_t size, const std::string& text) {
  if (message && size > 0) std::snprintf(message, size, "%s", text.c_str());
}

// Lays the model out in `block` (null: only measures it) and, when placing, copies the view in.
// Returns the block's size.
size_t layOut(const quiver::ModelView& view, bool single, const qv_allocator& allocator, char* block) {
  const quiver::ModelInfo& in = view.info;
  const size_t r = in.r, n = in.vertexCount;
  quiver::rt::BlockCarver c(block);
  qv_model* m = c.take<qv_model>(1);
  char* polynomial = c.take<char>(quiver::rt::ReducedPolynomial::storageBytes(in.r, single));
  float* basis32 = view.basis32 ? c.take<float>(3 * n * r) : nullptr;
  double* basis64 = view.basis32 ? nullptr : c.take<double>(3 * n * r);
  double* rest = c.take<double>(3 * n);
  unsigned* triangles = c.take<unsigned>(3 * size_t(in.triangleCount));
  unsigned* vertexMap = c.take<unsigned>(n);
  double* gravity = c.take<double>(3 * r);
  double* eigenvalues = c.take<double>(in.eigenvalueCount);
  double* rotations = view.rotations ? c.take<double>(3 * n * r) : nullptr;
  if (!block) return c.size();

  m = new (m) qv_model{};
  m->allocator = allocator;
  m->info = qv_model_info{static_cast<int>(in.r), static_cast<int>(in.vertexCount), static_cast<int>(in.tetCount),
                          static_cast<int>(in.triangleCount), static_cast<int>(in.fileVertexCount),
                          static_cast<int>(in.eigenvalueCount), static_cast<int>(in.basisPrecision),
                          static_cast<int>(in.materialIsUniform), view.rotations ? 1 : 0, in.youngsModulus, in.poissonRatio, in.density,
                          in.totalMass, in.rayleighAlpha, in.rayleighBeta, in.timeStep,
                          {in.bboxMin[0], in.bboxMin[1], in.bboxMin[2]}, {in.bboxMax[0], in.bboxMax[1], in.bboxMax[2]}};
  m->polynomial.build(in.r, view.energy, single, polynomial);
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
  return c.size();
}

qv_result build(const quiver::ModelView& view, const qv_model_config& config, const qv_allocator& allocator,
                qv_model** out) {
  const bool single = config.coefficient_precision == 32;
  const size_t bytes = layOut(view, single, allocator, nullptr);
  char* block = static_cast<char*>(allocator.allocate(bytes, 64, allocator.user));
  if (!block) return QV_ERROR_OUT_OF_MEMORY;
  layOut(view, single, allocator, block);
  *out = reinterpret_cast<qv_model*>(block);
  return QV_OK;
}

} // namespace

extern "C" {

void qv_model_config_init(qv_model_config* config) {
  if (config) config->coefficient_precision = 64;
}

void qv_allocator_init(qv_allocator* allocator) {
  if (allocator) *allocator = qv_allocator{heapAllocate, heapRelease, nullptr};
}

qv_result qv_model_load_memory(const void* data, size_t size, const qv_model_config* config,
                               const qv_allocator* allocator, qv_model** model, char* message, size_t message_size) {
  if (!model) return QV_ERROR_INVALID_ARGUMENT;
  *model = nullptr;
  qv_model_config defaults;
  qv_model_config_init(&defaults);
  const qv_model_config& settings = config ? *config : defaults;
  if ((!data && size) || (settings.coefficient_precision != 32 && settings.coefficient_precision != 64))
    return QV_ERROR_INVALID_ARGUMENT;
  qv_allocator heap;
  qv_allocator_init(&heap);
  const qv_allocator& use = allocator ? *allocator : heap;
  // parseModel wants an 8-byte aligned image; a caller's buffer may not be.
  void* aligned = nullptr;
  if (reinterpret_cast<uintptr_t>(data) % 8 != 0) {
    aligned = use.allocate(size ? size : 1, 64, use.user);
    if (!aligned) return QV_ERROR_OUT_OF_MEMORY;
    std::memcpy(aligned, data, size);
    data = aligned;
  }
  quiver::ModelView view;
  std::string error;
  qv_result result = QV_ERROR_FORMAT;
  if (quiver::parseModel(data, size, view, error))
    result = build(view, settings, use, model);
  else
    report(message, message_size, error);
  if (aligned) use.release(aligned, use.user);
  return result;
}

qv_result qv_model_load_file(const char* path, const qv_model_config* config, const qv_allocator* allocator,
                             qv_model** model, char* message, size_t message_size) {
  if (!model || !path) return QV_ERROR_INVALID_ARGUMENT;
  *model = nullptr;
  qv_allocator heap;
  qv_allocator_init(&heap);
  const qv_allocator& use = allocator ? *allocator : heap;
  FILE* file = std::fopen(path, "rb");
  if (!file) {
    report(message, message_size, std::string(path) + ": cannot open: " + std::strerror(errno));
    return QV_ERROR_IO;
  }
  std::fseek(file, 0, SEEK_END);
  const long length = std::ftell(file);
  std::fseek(file, 0, SEEK_SET);
  if (length < 0) {
    std::fclose(file);
    report(message, message_size, std::string(path) + ": cannot read its size");
    return QV_ERROR_IO;
  }
  void* buffer = use.allocate(length ? static_cast<size_t>(length) : 1, 64, use.user);
  if (!buffer) {
    std::fclose(file);
    return QV_ERROR_OUT_OF_MEMORY;
  }
  const bool complete = std::fread(buffer, 1, static_cast<size_t>(length), file) == static_cast<size_t>(length);
  std::fclose(file);
  qv_result result = QV_ERROR_IO;
  if (!complete) {
    report(message, message_size, std::string(path) + ": read error");
  } else {
    char inner[512] = "";
    result = qv_model_load_memory(buffer, static_cast<size_t>(length), config, &use, model, inner, sizeof inner);
    if (result != QV_OK) report(message, message_size, std::string(path) + ": " + inner);
  }
  use.release(buffer, use.user);
  return result;
}

void qv_model_destroy(qv_model* model) {
  if (!model) return;
  const qv_allocator allocator = model->allocator;
  model->~qv_model();
  allocator.release(model, allocator.user);
}

void qv_model_get_info(const qv_model* model, qv_model_info* info) {
  if (model && info) *info = model->info;
}

size_t qv_model_scratch_size(const qv_model* model) {
  return model ? quiver::rt::ReducedPolynomial::scratchSize(model->info.r) * sizeof(double) : 0;
}

qv_result qv_model_evaluate(const qv_model* model, const double* q, double* energy, double* force, double* stiffness,
                            void* scratch) {
  if (!model || !q || !scratch || reinterpret_cast<uintptr_t>(scratch) % alignof(double) != 0)
    return QV_ERROR_INVALID_ARGUMENT;
  model->polynomial.evaluate(q, energy, force, stiffness, static_cast<double*>(scratch));
  return QV_OK;
}

qv_result qv_model_displacements(const qv_model* model, const double* q, float* displacements) {
  if (!model || !q || !displacements) return QV_ERROR_INVALID_ARGUMENT;
  const size_t rows = 3 * static_cast<size_t>(model->info.vertex_count), r = model->info.r;
  for (size_t i = 0; i < rows; ++i) {
    double u = 0;
    if (model->basis32)
      for (size_t j = 0; j < r; ++j) u += static_cast<double>(model->basis32[i * r + j]) * q[j];
    else
      for (size_t j = 0; j < r; ++j) u += model->basis64[i * r + j] * q[j];
    displacements[i] = static_cast<float>(u);
  }
  return QV_OK;
}

const double* qv_model_rest_positions(const qv_model* model) { return model ? model->rest : nullptr; }
const unsigned* qv_model_triangles(const qv_model* model) { return model ? model->triangles : nullptr; }
const unsigned* qv_model_vertex_map(const qv_model* model) { return model ? model->vertexMap : nullptr; }
const double* qv_model_eigenvalues(const qv_model* model) { return model ? model->eigenvalues : nullptr; }
const double* qv_model_gravity(const qv_model* model) { return model ? model->gravity : nullptr; }

} // extern "C"
