// The C API: argument checks, then one call into the runtime's parts (model, instance, loads,
// integrators, elasticity, output). Nothing here computes.
#include <cerrno>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>

#include "c_enum.h"
#include "contact.h"
#include "elasticity.h"
#include "instance.h"
#include "integrators/integrator.h"
#include "model.h"
#include "output.h"
#include "render_mesh.h"
#include "step_many.h"
#include "triangle_mesh.h"
#include "world.h"
#include "quiver/quiver.h"

#define QV_STR2(x) #x
#define QV_STR(x) QV_STR2(x)

namespace {

using namespace quiver::rt;

void* heapAllocate(size_t size, size_t alignment, void*) {
  void* p = nullptr;
  return posix_memalign(&p, alignment < sizeof(void*) ? sizeof(void*) : alignment, size) == 0 ? p : nullptr;
}
void heapRelease(void* p, void*) { std::free(p); }

qv_allocator allocatorOr(const qv_allocator* allocator) {
  if (allocator) return *allocator;
  qv_allocator heap;
  qv_allocator_init(&heap);
  return heap;
}

// A caller's allocator needs both functions: one missing was called as address 0.
bool validAllocator(const qv_allocator* allocator) { return !allocator || (allocator->allocate && allocator->release); }
constexpr const char* kInvalidAllocator = "the qv_allocator has no allocate or no release function";

qv_model_config modelConfigOr(const qv_model_config* config) {
  if (config) return *config;
  qv_model_config defaults;
  qv_model_config_init(&defaults);
  return defaults;
}

void report(char* message, size_t size, const std::string& text) {
  if (message && size > 0) std::snprintf(message, size, "%s", text.c_str());
}

// What is wrong with these arguments of qv_model_load_*, or "" when nothing is.
std::string modelArgumentsError(const qv_model_config& config, const qv_allocator* allocator) {
  if (config.coefficient_precision != 32 && config.coefficient_precision != 64)
    return "qv_model_config.coefficient_precision is " + std::to_string(config.coefficient_precision) + ", not 32 or 64";
  if (config.group_layout < -1 || config.group_layout > 1)
    return "qv_model_config.group_layout is " + std::to_string(config.group_layout) + ", not -1, 0 or 1";
  if (!validAllocator(allocator)) return kInvalidAllocator;
  return "";
}

bool validVertex(const qv_instance* s, int vertex) { return vertex >= 0 && vertex < s->model->info.vertex_count; }

bool validVertices(const qv_instance* s, const int* vertices, int count) {
  for (int k = 0; k < count; ++k)
    if (!validVertex(s, vertices[k])) return false;
  return true;
}

// A field of row `index` of a name table, or null out of range (a C caller may pass any int as
// the enum: read it with cEnumValue()).
template <class Entry, size_t N>
const char* entry(const Entry (&table)[N], int index, const char* Entry::*field) {
  return index >= 0 && index < static_cast<int>(N) ? table[index].*field : nullptr;
}

template <class Table, class Enum>
qv_result fromName(const Table& table, const char* name, Enum* out) {
  if (!name || !out) return QV_ERROR_INVALID_ARGUMENT;
  for (const auto& entry : table)
    if (std::strcmp(entry.name, name) == 0) {
      *out = entry.id;
      return QV_OK;
    }
  return QV_ERROR_INVALID_ARGUMENT;
}

} // namespace

extern "C" {

const char* qv_version_string(void) {
  return QV_STR(QV_VERSION_MAJOR) "." QV_STR(QV_VERSION_MINOR) "." QV_STR(QV_VERSION_PATCH);
}

int qv_check_version(int version_number, size_t model_info_size, size_t instance_config_size) {
  return version_number == QV_VERSION_NUMBER && model_info_size == sizeof(qv_model_info) &&
         instance_config_size == sizeof(qv_instance_config);
}

const char* qv_result_string(qv_result result) {
  switch (cEnumValue(result)) {
    case QV_OK: return "ok";
    case QV_ERROR_INVALID_ARGUMENT: return "invalid argument";
    case QV_ERROR_IO: return "input/output error";
    case QV_ERROR_FORMAT: return "invalid model file";
    case QV_ERROR_OUT_OF_MEMORY: return "out of memory";
  }
  return "unknown result";
}

const char* qv_integrator_name(qv_integrator i) { return entry(kIntegrators, cEnumValue(i), &IntegratorEntry::name); }
const char* qv_integrator_description(qv_integrator i) {
  return entry(kIntegrators, cEnumValue(i), &IntegratorEntry::description);
}
qv_result qv_integrator_from_name(const char* name, qv_integrator* integrator) {
  return fromName(kIntegrators, name, integrator);
}
const char* qv_elasticity_name(qv_elasticity e) { return entry(kElasticities, cEnumValue(e), &ElasticityEntry::name); }
const char* qv_elasticity_description(qv_elasticity e) {
  return entry(kElasticities, cEnumValue(e), &ElasticityEntry::description);
}
qv_result qv_elasticity_from_name(const char* name, qv_elasticity* elasticity) {
  return fromName(kElasticities, name, elasticity);
}
const char* qv_solver_name(qv_solver v) { return entry(kSolvers, cEnumValue(v), &SolverEntry::name); }
const char* qv_solver_description(qv_solver v) { return entry(kSolvers, cEnumValue(v), &SolverEntry::description); }
qv_result qv_solver_from_name(const char* name, qv_solver* solver) { return fromName(kSolvers, name, solver); }

// ---- Models ----

void qv_model_config_init(qv_model_config* config) {
  if (config) *config = qv_model_config{64, -1};
}

void qv_allocator_init(qv_allocator* allocator) {
  if (allocator) *allocator = qv_allocator{heapAllocate, heapRelease, nullptr};
}

qv_result qv_model_load_memory(const void* data, size_t size, const qv_model_config* config,
                               const qv_allocator* allocator, qv_model** model, char* message, size_t message_size) {
  if (!model) return QV_ERROR_INVALID_ARGUMENT;
  *model = nullptr;
  const qv_model_config settings = modelConfigOr(config);
  std::string bad = modelArgumentsError(settings, allocator);
  if (!data && size) bad = "no data, but a size of " + std::to_string(size) + " bytes";
  if (!bad.empty()) {
    report(message, message_size, bad);
    return QV_ERROR_INVALID_ARGUMENT;
  }
  const qv_allocator use = allocatorOr(allocator);
  // The reader wants an 8-byte aligned image; a caller's buffer may not be.
  void* aligned = nullptr;
  if (reinterpret_cast<uintptr_t>(data) % 8 != 0) {
    aligned = use.allocate(size ? size : 1, 64, use.user);
    if (!aligned) return QV_ERROR_OUT_OF_MEMORY;
    std::memcpy(aligned, data, size);
    data = aligned;
  }
  const qv_result result = loadModel(data, size, settings, use, model, message, message_size);
  if (aligned) use.release(aligned, use.user);
  return result;
}

qv_result qv_model_load_file(const char* path, const qv_model_config* config, const qv_allocator* allocator,
                             qv_model** model, char* message, size_t message_size) {
  if (!model || !path) return QV_ERROR_INVALID_ARGUMENT;
  *model = nullptr;
  if (const std::string bad = modelArgumentsError(modelConfigOr(config), allocator); !bad.empty()) {
    report(message, message_size, std::string(path) + ": " + bad);
    return QV_ERROR_INVALID_ARGUMENT;
  }
  const qv_allocator use = allocatorOr(allocator);
  // fopen() opens a directory, whose size then reads as LONG_MAX.
  std::error_code error;
  if (std::filesystem::is_directory(path, error)) {
    report(message, message_size, std::string(path) + ": is a directory, not a model file");
    return QV_ERROR_IO;
  }
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
    report(message, message_size, std::string(path) + ": cannot allocate " + std::to_string(length) + " bytes to read it");
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
  if (model) destroyModel(model);
}

void qv_model_get_info(const qv_model* model, qv_model_info* info) {
  if (model && info) *info = model->info;
}

size_t qv_model_scratch_size(const qv_model* model) {
  return model ? ReducedPolynomial::scratchSize(model->info.r) * sizeof(double) : 0;
}

qv_result qv_model_evaluate(const qv_model* model, const double* q, double* energy, double* force, double* stiffness,
                            void* scratch) {
  if (!model || !q || !scratch || reinterpret_cast<uintptr_t>(scratch) % alignof(double) != 0)
    return QV_ERROR_INVALID_ARGUMENT;
  model->polynomial.evaluate(q, energy, force, stiffness, static_cast<double*>(scratch));
  return QV_OK;
}

qv_result qv_model_displacements(const qv_model* model, const double* q, float* out) {
  if (!model || !q || !out) return QV_ERROR_INVALID_ARGUMENT;
  displacements(*model, q, out);
  return QV_OK;
}

const double* qv_model_rest_positions(const qv_model* model) { return model ? model->rest : nullptr; }
const unsigned* qv_model_triangles(const qv_model* model) { return model ? model->triangles : nullptr; }
const unsigned* qv_model_vertex_map(const qv_model* model) { return model ? model->vertexMap : nullptr; }
const double* qv_model_eigenvalues(const qv_model* model) { return model ? model->eigenvalues : nullptr; }
const double* qv_model_gravity(const qv_model* model) { return model ? model->gravity : nullptr; }

void qv_model_surface_normals(const qv_model* model, const float* positions, float* normals) {
  if (model && positions && normals) surfaceNormals(*model, positions, normals);
}

// ---- Instances ----

void qv_instance_config_init(qv_instance_config* config, const qv_model* model) {
  if (config) defaultConfig(*config, model);
}

size_t qv_instance_memory_requirements(const qv_model* model, const qv_instance_config* config) {
  return validConfig(model, config) ? instanceBytes(*model, *config) : 0;
}

qv_result qv_instance_create_in_place(const qv_model* model, const qv_instance_config* config, void* memory,
                                      size_t size, qv_instance** instance) {
  if (!instance) return QV_ERROR_INVALID_ARGUMENT;
  *instance = nullptr;
  if (!validConfig(model, config) || !memory || reinterpret_cast<uintptr_t>(memory) % 64 != 0 ||
      size < instanceBytes(*model, *config))
    return QV_ERROR_INVALID_ARGUMENT;
  *instance = constructInstance(*model, *config, static_cast<char*>(memory));
  (*instance)->ownsMemory = false;
  return QV_OK;
}

qv_result qv_instance_create(const qv_model* model, const qv_instance_config* config, const qv_allocator* allocator,
                             qv_instance** instance) {
  if (!instance) return QV_ERROR_INVALID_ARGUMENT;
  *instance = nullptr;
  if (!validConfig(model, config) || !validAllocator(allocator)) return QV_ERROR_INVALID_ARGUMENT;
  const qv_allocator use = allocatorOr(allocator);
  char* block = static_cast<char*>(use.allocate(instanceBytes(*model, *config), 64, use.user));
  if (!block) return QV_ERROR_OUT_OF_MEMORY;
  *instance = constructInstance(*model, *config, block);
  (*instance)->allocator = use;
  (*instance)->ownsMemory = true;
  return QV_OK;
}

void qv_instance_destroy(qv_instance* s) {
  if (!s || !s->ownsMemory) return;
  const qv_allocator allocator = s->allocator;
  s->~qv_instance();
  allocator.release(s, allocator.user);
}

qv_step_status qv_instance_step(qv_instance* s) { return s->step(); }

size_t qv_instances_step_scratch_size(const qv_model* model, int jobs) {
  return model && jobs >= 1 ? quiver::rt::stepManyScratchPerJob(*model) * static_cast<size_t>(jobs) : 0;
}

qv_result qv_instances_step(qv_instance* const* instances, int count, const qv_job_runner* jobs, void* scratch,
                            size_t scratchSize, qv_step_status* statuses) {
  if (count < 0 || (count > 0 && !instances) || (jobs && (jobs->count < 1 || !jobs->run)))
    return QV_ERROR_INVALID_ARGUMENT;
  if (count == 0) return QV_OK;
  for (int i = 0; i < count; ++i)
    if (!instances[i] || instances[i]->model != instances[0]->model) return QV_ERROR_INVALID_ARGUMENT;
  const int jobCount = jobs ? jobs->count : 1;
  const size_t perJob = quiver::rt::stepManyScratchPerJob(*instances[0]->model);
  if (!scratch || reinterpret_cast<uintptr_t>(scratch) % 64 != 0 || scratchSize / perJob < static_cast<size_t>(jobCount))
    return QV_ERROR_INVALID_ARGUMENT;
  quiver::rt::stepMany(instances, count, jobs, scratch, statuses);
  return QV_OK;
}

void qv_instance_last_step(const qv_instance* s, qv_step_report* report) {
  if (s && report) *report = s->lastStep;
}

qv_result qv_instance_add_vertex_force(qv_instance* s, int vertex, const double force[3]) {
  if (!s || !force || !validVertex(s, vertex)) return QV_ERROR_INVALID_ARGUMENT;
  if (force[0] != 0 || force[1] != 0 || force[2] != 0) s->wake();  // a game's zero wind each frame lets it sleep
  s->addVertexForce(vertex, force);
  return QV_OK;
}

qv_result qv_instance_add_reduced_force(qv_instance* s, const double* force) {
  if (!s || !force) return QV_ERROR_INVALID_ARGUMENT;
  for (int i = 0; i < s->r; ++i)
    if (force[i] != 0) s->wake();
  s->loads.addReducedForce(force);
  return QV_OK;
}

void qv_instance_set_gravity(qv_instance* s, const double g[3]) {
  if (!s || !g) return;
  if (s->flying() && std::memcmp(g, s->frame.gravity, sizeof s->frame.gravity) != 0) s->wake();
  s->setGravity(g);
}

qv_result qv_instance_set_constraint(qv_instance* s, int slot, const int* vertices, int count, const double* targets,
                                     double stiffness) {
  if (!s || s->flying() || slot < 0 || slot >= s->config.max_constraints || count < 1 || !vertices || !targets ||
      !(stiffness > 0 && std::isfinite(stiffness)) || !validVertices(s, vertices, count) ||
      !std::all_of(targets, targets + 3 * static_cast<size_t>(count), [](double x) { return std::isfinite(x); }))
    return QV_ERROR_INVALID_ARGUMENT;
  s->loads.setConstraint(*s->model, slot, vertices, count, targets, stiffness);
  return QV_OK;
}

void qv_instance_clear_constraint(qv_instance* s, int slot) {
  if (s && slot >= 0 && slot < s->config.max_constraints) s->loads.clearConstraint(slot);
}

void qv_instance_get_state(const qv_instance* s, double* q, double* v, double* a) {
  if (!s) return;
  if (q) std::memcpy(q, s->q, sizeof(double) * s->r);
  if (v) std::memcpy(v, s->v, sizeof(double) * s->r);
  if (a) std::memcpy(a, s->a, sizeof(double) * s->r);
}

void qv_instance_set_state(qv_instance* s, const double* q, const double* v, const double* a) {
  if (!s) return;
  s->wake();
  s->setState(q, v, a);
}

size_t qv_instance_snapshot_size(const qv_instance* s) { return s ? s->snapshotSize() : 0; }

size_t qv_instance_save_snapshot(const qv_instance* s, void* snapshot) {
  return s && snapshot ? s->saveSnapshot(static_cast<double*>(snapshot)) : 0;
}

qv_result qv_instance_restore_snapshot(qv_instance* s, const void* snapshot, size_t size) {
  if (!s || !snapshot || reinterpret_cast<uintptr_t>(snapshot) % alignof(double) != 0) return QV_ERROR_INVALID_ARGUMENT;
  if (!s->restoreSnapshot(static_cast<const double*>(snapshot), size)) return QV_ERROR_INVALID_ARGUMENT;
  s->wake();
  return QV_OK;
}

void qv_instance_reset(qv_instance* s) {
  if (!s) return;
  s->wake();
  s->rest();
}

void qv_instance_energies(const qv_instance* s, double* kinetic, double* elastic) {
  if (s) s->energies(kinetic, elastic);
}

qv_result qv_instance_get_rigid_state(const qv_instance* s, qv_rigid_state* state) {
  if (!s || !state || !s->flying()) return QV_ERROR_INVALID_ARGUMENT;
  quiver::rt::RigidFrame f = s->frame;  // refreshed on the side: a query changes no state
  f.refresh(*s->model, s->q, s->v);
  std::memcpy(state->position, f.position, sizeof state->position);
  std::memcpy(state->orientation, f.orientation, sizeof state->orientation);
  std::memcpy(state->linear_velocity, f.velocity, sizeof state->linear_velocity);
  f.worldOmega(state->angular_velocity);
  return QV_OK;
}

qv_result qv_instance_set_rigid_state(qv_instance* s, const qv_rigid_state* state) {
  if (!s || !state || !s->flying()) return QV_ERROR_INVALID_ARGUMENT;
  double norm = 0;
  for (double w : state->orientation) norm += w * w;
  for (int a = 0; a < 3; ++a)
    if (!std::isfinite(state->position[a]) || !std::isfinite(state->linear_velocity[a]) ||
        !std::isfinite(state->angular_velocity[a]))
      return QV_ERROR_INVALID_ARGUMENT;
  if (!(norm > 0) || !std::isfinite(norm)) return QV_ERROR_INVALID_ARGUMENT;
  s->wake();
  quiver::rt::RigidFrame& f = s->frame;
  std::memcpy(f.position, state->position, sizeof f.position);
  f.setOrientation(state->orientation);
  std::memcpy(f.velocity, state->linear_velocity, sizeof f.velocity);
  std::memcpy(f.homePosition, f.position, sizeof f.homePosition);
  std::memcpy(f.homeOrientation, f.orientation, sizeof f.homeOrientation);
  f.refresh(*s->model, s->q, s->v);
  f.setWorldOmega(state->angular_velocity);
  // A new spin is a new state: q'' at once what the new centrifugal force gives.
  s->setState(nullptr, s->v, nullptr);
  return QV_OK;
}

namespace {

bool validColliders(const qv_collider* colliders, int count) {
  if (count < 0 || (count > 0 && !colliders)) return false;
  for (int k = 0; k < count; ++k)
    if (!validCollider(colliders[k])) return false;
  return true;
}

int copyContacts(const ContactList& list, qv_contact* out, int capacity) {
  for (int j = 0; out && j < std::min(capacity, list.count); ++j) {
    const Contact& c = list.contacts[j];
    qv_contact& o = out[j];
    o.vertex = c.vertex;
    o.collider = c.collider;
    o.instance = c.body;
    o.other = c.other;
    o.depth = c.deformedDepth;
    for (int a = 0; a < 3; ++a) {
      o.point[a] = c.point[a];
      o.normal[a] = c.normal[a];
      o.impulse[a] = c.normalImpulse * c.normal[a] + c.tangentImpulse[0] * c.tangent[0][a] + c.tangentImpulse[1] * c.tangent[1][a];
    }
  }
  return list.count;
}

} // namespace

qv_result qv_instance_set_colliders(qv_instance* s, const qv_collider* colliders, int count) {
  if (!s || !s->flying() || !validColliders(colliders, count)) return QV_ERROR_INVALID_ARGUMENT;
  s->colliders = count ? colliders : nullptr;
  s->colliderCount = count;
  return QV_OK;
}

int qv_instance_contacts(const qv_instance* s, qv_contact* out, int capacity) {
  if (!s) return 0;
  return copyContacts(s->contacts, out, capacity);
}

qv_result qv_triangle_mesh_create(const double* positions, int vertex_count, const int* triangles, int triangle_count,
                                  const qv_allocator* allocator, qv_triangle_mesh** mesh, char* message, size_t message_size) {
  if (!mesh) return QV_ERROR_INVALID_ARGUMENT;
  *mesh = nullptr;
  const char* bad = !validAllocator(allocator)    ? kInvalidAllocator
                    : !positions || !triangles      ? "no positions or no triangles"
                    : vertex_count < 0 || triangle_count < 0 ? "a negative vertex or triangle count"
                                                              : nullptr;
  if (bad) {
    report(message, message_size, bad);
    return QV_ERROR_INVALID_ARGUMENT;
  }
  return createTriangleMesh(positions, vertex_count, triangles, triangle_count, allocatorOr(allocator), mesh, message,
                            message_size);
}

void qv_triangle_mesh_destroy(qv_triangle_mesh* mesh) {
  if (mesh) destroyTriangleMesh(mesh);
}

void qv_world_config_init(qv_world_config* config) {
  if (config) defaultWorldConfig(*config);
}

qv_result qv_world_create(const qv_world_config* config, const qv_allocator* allocator, qv_world** world) {
  if (!world) return QV_ERROR_INVALID_ARGUMENT;
  *world = nullptr;
  qv_world_config settings;
  defaultWorldConfig(settings);
  if (config) settings = *config;
  if (!validWorldConfig(settings) || !validAllocator(allocator)) return QV_ERROR_INVALID_ARGUMENT;
  *world = createWorld(settings, allocatorOr(allocator));
  return *world ? QV_OK : QV_ERROR_OUT_OF_MEMORY;
}

void qv_world_destroy(qv_world* world) {
  if (world) destroyWorld(world);
}

qv_result qv_world_add(qv_world* world, qv_instance* instance, int* index) {
  if (!world || !instance || !instance->flying() || world->count == world->config.max_instances)
    return QV_ERROR_INVALID_ARGUMENT;
  for (int i = 0; i < world->count; ++i)
    if (world->instances[i] == instance || world->instances[i]->config.time_step != instance->config.time_step)
      return QV_ERROR_INVALID_ARGUMENT;
  if (index) *index = world->count;
  world->instances[world->count++] = instance;
  return QV_OK;
}

qv_result qv_world_remove(qv_world* world, qv_instance* instance) {
  if (!world || !instance) return QV_ERROR_INVALID_ARGUMENT;
  for (int i = 0; i < world->count; ++i)
    if (world->instances[i] == instance) {
      world->remove(i);
      return QV_OK;
    }
  return QV_ERROR_INVALID_ARGUMENT;
}

qv_result qv_world_set_colliders(qv_world* world, const qv_collider* colliders, int count) {
  if (!world || !validColliders(colliders, count)) return QV_ERROR_INVALID_ARGUMENT;
  world->colliders = count ? colliders : nullptr;
  world->colliderCount = count;
  for (int i = 0; i < world->count; ++i) world->instances[i]->wake();
  return QV_OK;
}

qv_result qv_world_set_jobs(qv_world* world, const qv_job_runner* jobs) {
  if (!world || (jobs && (jobs->count < 1 || !jobs->run))) return QV_ERROR_INVALID_ARGUMENT;
  world->jobs = jobs;
  return QV_OK;
}

int qv_world_step(qv_world* world) { return world ? world->step() : 0; }

int qv_instance_asleep(const qv_instance* s) { return s && s->asleep; }

void qv_instance_wake(qv_instance* s) {
  if (s) s->wake();
}

size_t qv_world_snapshot_size(const qv_world* world) { return world ? world->snapshotSize() : 0; }

size_t qv_world_save_snapshot(const qv_world* world, void* snapshot) {
  return world && snapshot ? world->saveSnapshot(static_cast<double*>(snapshot)) : 0;
}

qv_result qv_world_restore_snapshot(qv_world* world, const void* snapshot, size_t size) {
  if (!world || !snapshot || reinterpret_cast<uintptr_t>(snapshot) % alignof(double) != 0) return QV_ERROR_INVALID_ARGUMENT;
  return world->restoreSnapshot(static_cast<const double*>(snapshot), size) ? QV_OK : QV_ERROR_INVALID_ARGUMENT;
}

int qv_world_contacts(const qv_world* world, qv_contact* contacts, int capacity) {
  return world ? copyContacts(world->contacts, contacts, capacity) : 0;
}

double qv_instance_stable_time_step(const qv_instance* s) {
  if (!s) return 0;
  // A mode of K(0) (omega^2 = lambda) under Rayleigh damping c = alpha + beta lambda, stepped as
  // stepCentralDifferences() steps it (damping at the predicted velocity), is stable below
  // 2 / (c + sqrt(c^2 + lambda)); that falls with lambda, so the stiffest mode sets the limit. With
  // beta = 0.01 s and omega_max = 2900 rad/s, 12 us where 2 / omega_max says 690.
  const double lambda = s->model->largestEigenvalue;
  const double c = s->config.rayleigh_alpha + s->config.rayleigh_beta * lambda;
  return c > 0 || lambda > 0 ? 2 / (c + std::sqrt(c * c + lambda)) : INFINITY;
}

const float* qv_model_render_rest_positions(const qv_model* m) { return m ? m->render.rest : nullptr; }
const unsigned* qv_model_render_triangles(const qv_model* m) { return m ? m->render.triangles : nullptr; }
const float* qv_model_render_normals(const qv_model* m) { return m ? m->render.normals : nullptr; }
const float* qv_model_render_uvs(const qv_model* m) { return m ? m->render.uvs : nullptr; }

size_t qv_model_render_scratch_size(const qv_model* m) {
  return m ? m->render.scratchBytes(m->info.vertex_count, m->info.tet_count) : 0;
}

qv_result qv_instance_render(const qv_instance* s, float* positions, float* normals, void* scratch) {
  if (!s || !positions || !scratch || !s->model->render.vertexCount) return QV_ERROR_INVALID_ARGUMENT;
  renderOutput(*s, positions, normals, scratch);
  return QV_OK;
}

void qv_instance_positions(const qv_instance* s, float* out) {
  if (s && out) positions(*s, out);
}

qv_result qv_instance_positions_of(const qv_instance* s, const int* vertices, int count, float* out) {
  if (!s || !vertices || !out || count < 0 || !validVertices(s, vertices, count)) return QV_ERROR_INVALID_ARGUMENT;
  positionsOf(*s, vertices, count, out);
  return QV_OK;
}

} // extern "C"
