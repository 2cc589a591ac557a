/* Quiver runtime: real-time reduced St.Venant-Kirchhoff deformables. C API, usable from C, C++
   and other languages' FFI. Conventions: qv_ prefix; opaque handles; plain C types; every
   fallible call returns a qv_result and, where useful, a readable message; nothing throws.

   A qv_model is an immutable baked model (a .qvr file): load it once and share it read-only
   between any number of simulations and threads. */
#ifndef QUIVER_H
#define QUIVER_H

#include <stddef.h>

#include "quiver/quiver_config.h"

#ifdef __cplusplus
extern "C" {
#endif

#define QV_VERSION_MAJOR 0
#define QV_VERSION_MINOR 1
#define QV_VERSION_PATCH 0
#define QV_VERSION_NUMBER (QV_VERSION_MAJOR * 10000 + QV_VERSION_MINOR * 100 + QV_VERSION_PATCH)

/* The library's version as "major.minor.patch". */
QV_API const char* qv_version_string(void);

/* Non-zero when the library this program links was built from the headers it was compiled with
   (same version and struct sizes); call once at start-up as QV_CHECK_VERSION(). */
QV_API int qv_check_version(int version_number, size_t model_info_size, size_t allocator_size);
#define QV_CHECK_VERSION() qv_check_version(QV_VERSION_NUMBER, sizeof(qv_model_info), sizeof(qv_allocator))

typedef enum qv_result {
  QV_OK = 0,
  QV_ERROR_INVALID_ARGUMENT = 1, /* a null pointer or a size that does not fit */
  QV_ERROR_IO = 2,               /* the file could not be read */
  QV_ERROR_FORMAT = 3,           /* not a valid .qvr file (the message says where and why) */
  QV_ERROR_OUT_OF_MEMORY = 4
} qv_result;

/* A short description of a result code ("invalid argument", ...). */
QV_API const char* qv_result_string(qv_result result);

/* Where the library's memory comes from. Fill with qv_allocator_init() (the C heap), then replace
   the functions to route allocations through your engine. `alignment` is a power of two <= 64. */
typedef struct qv_allocator {
  void* (*allocate)(size_t size, size_t alignment, void* user);
  void (*release)(void* pointer, void* user);
  void* user;
} qv_allocator;
QV_API void qv_allocator_init(qv_allocator* allocator);

typedef struct qv_model qv_model;

/* Summary of a model. Units are those the model was baked in (SI: m, kg, s, Pa). */
typedef struct qv_model_info {
  int r;                     /* reduced coordinates q */
  int vertex_count;          /* simulated vertices */
  int tet_count;
  int triangle_count;        /* surface triangles for rendering */
  int file_vertex_count;     /* vertices of the mesh file the model was baked from */
  int eigenvalue_count;
  int basis_precision;       /* 32 or 64 bits per stored basis entry */
  int material_is_uniform;   /* 1: one material; 0: mixed (the values below are volume-weighted means) */
  double youngs_modulus;     /* Pa */
  double poisson_ratio;
  double density;            /* kg/m^3 */
  double total_mass;         /* kg */
  double rayleigh_alpha;     /* default damping alpha I + beta K(q): 1/s */
  double rayleigh_beta;      /* s */
  double time_step;          /* suggested, s */
  double bbox_min[3], bbox_max[3];
} qv_model_info;

/* Loads a .qvr file or a .qvr image in memory (copied; the caller may free it afterwards).
   `allocator` may be NULL for the C heap. On failure *model is NULL and, when `message` is not
   NULL, it receives a NUL-terminated description (file, section, offset, what is wrong),
   truncated to `message_size` bytes. */
QV_API qv_result qv_model_load_file(const char* path, const qv_allocator* allocator, qv_model** model,
                                    char* message, size_t message_size);
QV_API qv_result qv_model_load_memory(const void* data, size_t size, const qv_allocator* allocator,
                                      qv_model** model, char* message, size_t message_size);
QV_API void qv_model_destroy(qv_model* model);

QV_API void qv_model_get_info(const qv_model* model, qv_model_info* info);

/* Bytes of scratch memory qv_model_evaluate needs (a few kilobytes; 8-byte aligned). */
QV_API size_t qv_model_scratch_size(const qv_model* model);

/* The reduced elastic model at q (r values): energy E(q), internal force R(q) = dE/dq (r values)
   and stiffness K(q) = dR/dq (r x r, row-major, symmetric). Any output may be NULL. Thread-safe
   for distinct scratch buffers; allocates nothing. */
QV_API qv_result qv_model_evaluate(const qv_model* model, const double* q, double* energy, double* force,
                                   double* stiffness, void* scratch);

/* The stored model data, read-only, valid while the model lives (NULL when absent):
   rest positions (3 per vertex), surface triangles (3 vertex indices each), each vertex's index in
   the mesh file, the eigenvalues, and the gravity projection (3 x r: row a = U^T M e_a). */
QV_API const double* qv_model_rest_positions(const qv_model* model);
QV_API const unsigned* qv_model_triangles(const qv_model* model);
QV_API const unsigned* qv_model_vertex_map(const qv_model* model);
QV_API const double* qv_model_eigenvalues(const qv_model* model);
QV_API const double* qv_model_gravity(const qv_model* model);

/* Displacements u = U q of every vertex into `displacements` (3 floats per vertex). */
QV_API qv_result qv_model_displacements(const qv_model* model, const double* q, float* displacements);

#ifdef __cplusplus
}
#endif

#endif
