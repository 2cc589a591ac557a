// The real-time contract: after creation, stepping and reading positions never allocate (counted by
// interposing malloc for the whole test binary), and all of the library's own memory goes
// through the caller's allocator.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <string>

#include "tests/runtime/runtime_fixture.h"

extern "C" void* __libc_malloc(size_t);
extern "C" void* __libc_calloc(size_t, size_t);
extern "C" void* __libc_realloc(void*, size_t);
extern "C" int __posix_memalign(void**, size_t, size_t);

namespace {
std::atomic<long> heapCalls{0};
}

// Every heap allocation in this process passes here (operator new too, through malloc).
extern "C" void* malloc(size_t size) {
  heapCalls.fetch_add(1, std::memory_order_relaxed);
  return __libc_malloc(size);
}
extern "C" void* calloc(size_t n, size_t size) {
  heapCalls.fetch_add(1, std::memory_order_relaxed);
  return __libc_calloc(n, size);
}
extern "C" void* realloc(void* p, size_t size) {
  heapCalls.fetch_add(1, std::memory_order_relaxed);
  return __libc_realloc(p, size);
}

namespace {

struct CountingAllocator {
  long allocations = 0, releases = 0;
  static void* allocate(size_t size, size_t alignment, void* user) {
    ++static_cast<CountingAllocator*>(user)->allocations;
    return std::aligned_alloc(alignment, (size + alignment - 1) / alignment * alignment);
  }
  static void release(void* p, void* user) {
    ++static_cast<CountingAllocator*>(user)->releases;
    std::free(p);
  }
};

} // namespace

TEST(RealTime, StepAndOutputAllocateNothing) {
  quiver::test::TestModel m;
  ASSERT_NE(m.model, nullptr);
  CountingAllocator counter;
  const qv_allocator allocator{CountingAllocator::allocate, CountingAllocator::release, &counter};
  qv_instance_config config;
  qv_instance_config_init(&config, m.model);
  for (qv_integrator integrator :
       {QV_INTEGRATOR_IMPLICIT_NEWMARK, QV_INTEGRATOR_BACKWARD_EULER, QV_INTEGRATOR_CENTRAL_DIFFERENCES}) {
    config.integrator = integrator;
    config.time_step = integrator == QV_INTEGRATOR_CENTRAL_DIFFERENCES ? 1e-4 : 1.0 / 60;
    qv_instance* s = nullptr;
    ASSERT_EQ(qv_instance_create(m.model, &config, &allocator, &s), QV_OK);
    const int tip = m.tipVertex();
    std::vector<float> positions(3 * m.info.vertex_count), normals(positions.size());
    std::vector<double> reduced(m.info.r, 0.1);
    const double g[3] = {0, 0, -9.81}, push[3] = {0, 1, 0}, target[3] = {0.6, 0.05, 0.1};
    const long probe = heapCalls.load();
    std::vector<int> allocates(16);
    ASSERT_GT(heapCalls.load(), probe) << "malloc is not interposed: the count below would prove nothing";
    const long before = heapCalls.load();
    qv_instance_set_gravity(s, g);
    qv_instance_set_constraint(s, 1, &tip, 1, target, 1e3);
    for (int step = 0; step < 100; ++step) {
      qv_instance_add_vertex_force(s, tip, push);
      qv_instance_add_reduced_force(s, reduced.data());
      qv_instance_step(s);
      qv_instance_positions(s, positions.data());
      qv_model_surface_normals(m.model, positions.data(), normals.data());
    }
    EXPECT_EQ(heapCalls.load() - before, 0) << "integrator " << integrator;
    qv_instance_destroy(s);
  }
  EXPECT_EQ(counter.allocations, 3);  // one block per instance
  EXPECT_EQ(counter.releases, 3);
}

TEST(RealTime, SteppingManyAllocatesNothing) {
  quiver::test::TestModel m;
  ASSERT_NE(m.model, nullptr);
  qv_instance_config config;
  qv_instance_config_init(&config, m.model);
  std::vector<qv_instance*> instances(11);
  for (auto& s : instances) ASSERT_EQ(qv_instance_create(m.model, &config, nullptr, &s), QV_OK);
  const size_t bytes = qv_instances_step_scratch_size(m.model, 1);
  void* scratch = std::aligned_alloc(64, (bytes + 63) / 64 * 64);
  std::vector<qv_step_status> statuses(instances.size());
  const double g[3] = {0, 0, -9.81};
  const long before = heapCalls.load();
  for (int step = 0; step < 50; ++step) {
    for (qv_instance* s : instances) qv_instance_set_gravity(s, g);
    EXPECT_EQ(qv_instances_step(instances.data(), static_cast<int>(instances.size()), nullptr, scratch, bytes,
                                statuses.data()),
              QV_OK);
  }
  EXPECT_EQ(heapCalls.load() - before, 0);
  std::free(scratch);
  for (qv_instance* s : instances) qv_instance_destroy(s);
}

TEST(RealTime, InstanceInCallerMemoryAndModelThroughCallerAllocator) {
  quiver::test::TestModel m;
  ASSERT_NE(m.model, nullptr);
  CountingAllocator counter;
  const qv_allocator allocator{CountingAllocator::allocate, CountingAllocator::release, &counter};
  qv_model* model = nullptr;
  char message[256];
  ASSERT_EQ(qv_model_load_file(QUIVER_RUNTIME_MODEL, nullptr, &allocator, &model, message, sizeof message), QV_OK);
  EXPECT_EQ(counter.allocations, 2);  // the file image, then the model's one block
  EXPECT_EQ(counter.releases, 1);     // the image
  qv_instance_config config;
  qv_instance_config_init(&config, model);
  const size_t bytes = qv_instance_memory_requirements(model, &config);
  void* block = std::aligned_alloc(64, (bytes + 63) / 64 * 64);
  qv_instance* s = nullptr;
  EXPECT_EQ(qv_instance_create_in_place(model, &config, block, bytes - 1, &s), QV_ERROR_INVALID_ARGUMENT);
  ASSERT_EQ(qv_instance_create_in_place(model, &config, block, bytes, &s), QV_OK);
  EXPECT_EQ(qv_instance_step(s), QV_STEP_OK);
  qv_instance_destroy(s);  // frees nothing: the block is the caller's
  std::free(block);
  qv_model_destroy(model);
  EXPECT_EQ(counter.releases, 2);
}

TEST(RealTime, BadArgumentsAreRefusedNotCrashed) {
  quiver::test::TestModel m;
  ASSERT_NE(m.model, nullptr);
  qv_instance_config config;
  qv_instance_config_init(&config, m.model);
  qv_instance* s = nullptr;
  qv_instance_config bad = config;
  bad.time_step = -1;
  EXPECT_EQ(qv_instance_create(m.model, &bad, nullptr, &s), QV_ERROR_INVALID_ARGUMENT);
  bad.time_step = 1e-300;  // 1 / h^2 overflows: refused, not left to go non-finite
  EXPECT_EQ(qv_instance_create(m.model, &bad, nullptr, &s), QV_ERROR_INVALID_ARGUMENT);
  bad = config;
  bad.newton_iterations = 0;
  EXPECT_EQ(qv_instance_create(m.model, &bad, nullptr, &s), QV_ERROR_INVALID_ARGUMENT);
  for (const int substeps : {0, 65}) {
    bad = config;
    bad.max_substeps = substeps;
    EXPECT_EQ(qv_instance_create(m.model, &bad, nullptr, &s), QV_ERROR_INVALID_ARGUMENT) << substeps;
  }
  EXPECT_EQ(qv_instance_create(nullptr, &config, nullptr, &s), QV_ERROR_INVALID_ARGUMENT);
  ASSERT_EQ(qv_instance_create(m.model, &config, nullptr, &s), QV_OK);
  const double f[3] = {1, 0, 0};
  EXPECT_EQ(qv_instance_add_vertex_force(s, -1, f), QV_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(qv_instance_add_vertex_force(s, m.info.vertex_count, f), QV_ERROR_INVALID_ARGUMENT);
  const int v = 0;
  EXPECT_EQ(qv_instance_set_constraint(s, config.max_constraints, &v, 1, f, 1), QV_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(qv_instance_set_constraint(s, 0, &v, 1, f, -1), QV_ERROR_INVALID_ARGUMENT);
  // Non-finite springs and targets (an infinite stiffness was taken, and every step then reset).
  EXPECT_EQ(qv_instance_set_constraint(s, 0, &v, 1, f, INFINITY), QV_ERROR_INVALID_ARGUMENT);
  const double far[3] = {1, NAN, 0};
  EXPECT_EQ(qv_instance_set_constraint(s, 0, &v, 1, far, 1), QV_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(qv_instance_set_constraint(s, 0, &v, 1, f, 1), QV_OK);
  qv_instance_destroy(s);
  qv_model* model = nullptr;
  EXPECT_EQ(qv_model_load_memory("not a model", 11, nullptr, nullptr, &model, nullptr, 0), QV_ERROR_FORMAT);
  EXPECT_EQ(model, nullptr);
  // Invalid arguments say which, in the message (it was left as it was), for memory and file alike.
  qv_model_config precision;
  qv_model_config_init(&precision);
  precision.coefficient_precision = 16;
  qv_model_config layout;
  qv_model_config_init(&layout);
  layout.group_layout = 7;
  qv_allocator half;
  qv_allocator_init(&half);
  half.allocate = nullptr;  // was called as address 0
  const struct {
    const qv_model_config* config;
    const qv_allocator* allocator;
    const char* says;
  } cases[] = {{&precision, nullptr, "coefficient_precision is 16, not 32 or 64"},
               {&layout, nullptr, "group_layout is 7, not -1, 0 or 1"},
               {nullptr, &half, "qv_allocator has no allocate or no release function"}};
  for (const auto& c : cases) {
    char message[256];
    std::memset(message, 'x', sizeof message);
    EXPECT_EQ(qv_model_load_memory("not a model", 11, c.config, c.allocator, &model, message, sizeof message),
              QV_ERROR_INVALID_ARGUMENT);
    EXPECT_NE(std::strstr(message, c.says), nullptr) << std::string(message, strnlen(message, sizeof message));
    std::memset(message, 'x', sizeof message);
    EXPECT_EQ(qv_model_load_file(QUIVER_RUNTIME_MODEL, c.config, c.allocator, &model, message, sizeof message),
              QV_ERROR_INVALID_ARGUMENT);
    EXPECT_NE(std::strstr(message, c.says), nullptr) << std::string(message, strnlen(message, sizeof message));
    EXPECT_NE(std::strstr(message, QUIVER_RUNTIME_MODEL), nullptr);
    EXPECT_EQ(model, nullptr);
  }
  EXPECT_EQ(qv_instance_create(m.model, &config, &half, &s), QV_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(s, nullptr);
  // A triangle mesh's bad counts are said too (the message held the previous call's).
  char message[128] = "previous";
  qv_triangle_mesh* mesh = nullptr;
  const double positions[3] = {0, 0, 0};
  const int triangles[3] = {0, 0, 0};
  EXPECT_EQ(qv_triangle_mesh_create(positions, -4, triangles, 1, nullptr, &mesh, message, sizeof message),
            QV_ERROR_INVALID_ARGUMENT);
  EXPECT_STREQ(message, "a negative vertex or triangle count");
  qv_world* world = nullptr;
  EXPECT_EQ(qv_world_create(nullptr, &half, &world), QV_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(world, nullptr);
}
