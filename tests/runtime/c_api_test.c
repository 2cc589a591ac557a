/* The C API from C: every call a C program (or an FFI) makes, on the suite's baked model.
   Exits non-zero, naming the check, on the first failure. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "quiver/quiver.h"

#define CHECK(condition)                                              \
  do {                                                                \
    if (!(condition)) {                                               \
      fprintf(stderr, "%s:%d: check failed: %s\n", __FILE__, __LINE__, #condition); \
      return 1;                                                       \
    }                                                                 \
  } while (0)

static int jobs_run = 0;
static void run_jobs(void* user, qv_job_function job, void* data, int count) {
  (void)user;
  for (int i = 0; i < count; ++i, ++jobs_run) job(data, i);
}

int main(int argc, char** argv) {
  CHECK(argc == 2);
  CHECK(QV_CHECK_VERSION());
  CHECK(!qv_check_version(QV_VERSION_NUMBER + 1, sizeof(qv_model_info), sizeof(qv_instance_config)));

  qv_model* model = NULL;
  char message[256];
  CHECK(qv_model_load_file("/nonexistent.qvr", NULL, NULL, &model, message, sizeof message) == QV_ERROR_IO && !model);
  CHECK(strstr(message, "/nonexistent.qvr: cannot open") == message);
  /* fopen() opens a directory, and its size reads as LONG_MAX: it once failed as out of memory, unsaid. */
  CHECK(qv_model_load_file("/", NULL, NULL, &model, message, sizeof message) == QV_ERROR_IO && !model);
  CHECK(strcmp(message, "/: is a directory, not a model file") == 0);
  CHECK(qv_model_load_file(argv[1], NULL, NULL, &model, message, sizeof message) == QV_OK && model);
  qv_model_info info;
  qv_model_get_info(model, &info);
  CHECK(info.r > 0 && info.vertex_count > 0 && info.triangle_count > 0 && info.total_mass > 0);

  qv_instance_config config;
  qv_instance_config_init(&config, model);
  CHECK(config.integrator == QV_INTEGRATOR_IMPLICIT_NEWMARK && config.solver == QV_SOLVER_MINIMIZE && config.newton_iterations == 8);
  qv_instance* instance = NULL;
  CHECK(qv_instance_create(model, &config, NULL, &instance) == QV_OK);
  const double gravity[3] = {0, 0, -9.81};
  qv_instance_set_gravity(instance, gravity);
  for (int step = 0; step < 100; ++step) CHECK(qv_instance_step(instance) != QV_STEP_RESET);

  float* positions = malloc(sizeof(float) * 3 * (size_t)info.vertex_count);
  CHECK(positions);
  qv_instance_positions(instance, positions);
  double lowest = 1e300;
  for (int v = 0; v < info.vertex_count; ++v) lowest = fmin(lowest, positions[3 * v + 2]);
  CHECK(lowest < info.bbox_min[2]);  /* gravity pulled it down */
  double kinetic = -1, elastic = -1;
  qv_instance_energies(instance, &kinetic, &elastic);
  CHECK(kinetic >= 0 && elastic > 0);
  qv_instance_reset(instance);
  qv_instance_energies(instance, &kinetic, &elastic);
  CHECK(kinetic == 0 && elastic == 0);
  CHECK(qv_result_string(QV_ERROR_FORMAT)[0] != '\0');
  /* Any int is a valid enum value in C: out of range, names are null and results "unknown". */
  CHECK(strcmp(qv_result_string((qv_result)42), "unknown result") == 0);
  CHECK(qv_solver_name((qv_solver)9) == NULL && qv_integrator_description((qv_integrator)-1) == NULL);
  CHECK(qv_elasticity_name((qv_elasticity)7) == NULL && strcmp(qv_solver_name(QV_SOLVER_MINIMIZE), "minimize") == 0);

  /* A crowd in one call (9 instances: 2 jobs of a group each), its pieces run by a job runner of
     our own (here: one after the other). */
  enum { CROWD = 9 };
  qv_instance* crowd[CROWD] = {instance};
  for (int i = 1; i < CROWD; ++i) CHECK(qv_instance_create(model, &config, NULL, &crowd[i]) == QV_OK);
  const qv_job_runner jobs = {2, run_jobs, NULL};
  const size_t bytes = qv_instances_step_scratch_size(model, jobs.count);
  char* block = malloc(bytes + 63); /* C99 has no aligned_alloc: align by hand */
  CHECK(block);
  void* scratch = block + (64 - (uintptr_t)block % 64) % 64;
  qv_step_status statuses[CROWD];
  for (int step = 0; step < 10; ++step) {
    CHECK(qv_instances_step(crowd, CROWD, &jobs, scratch, bytes, statuses) == QV_OK);
    for (int i = 0; i < CROWD; ++i) CHECK(statuses[i] != QV_STEP_RESET);
  }
  CHECK(jobs_run == 10 * jobs.count);
  free(block);
  for (int i = 1; i < CROWD; ++i) qv_instance_destroy(crowd[i]);

  free(positions);
  qv_instance_destroy(instance);
  qv_model_destroy(model);
  printf("c api: ok (r = %d)\n", info.r);
  return 0;
}
