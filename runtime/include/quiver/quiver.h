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
#define QV_VERSION_MINOR 16
#define QV_VERSION_PATCH 0
#define QV_VERSION_NUMBER (QV_VERSION_MAJOR * 10000 + QV_VERSION_MINOR * 100 + QV_VERSION_PATCH)

/* The library's version as "major.minor.patch". */
QV_API const char* qv_version_string(void);

/* Non-zero when the library this program links was built from the headers it was compiled with
   (same version and struct sizes); call once at start-up as QV_CHECK_VERSION(). */
QV_API int qv_check_version(int version_number, size_t model_info_size, size_t instance_config_size);
#define QV_CHECK_VERSION() qv_check_version(QV_VERSION_NUMBER, sizeof(qv_model_info), sizeof(qv_instance_config))

/* Standard gravity, m/s^2: what the tools, the bake's fidelity report and the examples mean by "gravity". */
#define QV_STANDARD_GRAVITY 9.81

/* The smallest time step an instance takes (qv_instance_config.time_step), s: 1 / h^2, by which the
   implicit integrators scale, stays far from overflowing. */
#define QV_MIN_TIME_STEP 1e-12

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
  int has_modal_rotations;   /* 1: the model can be simulated with modal warping */
  int has_rigid_body;        /* 1: baked free (no fixed vertex), with its mass moments: instances can fly */
  double youngs_modulus;     /* Pa */
  double poisson_ratio;
  double density;            /* kg/m^3 */
  double total_mass;         /* kg */
  double rayleigh_alpha;     /* default damping alpha I + beta K(q): 1/s */
  double rayleigh_beta;      /* s */
  double time_step;          /* suggested, s */
  double bbox_min[3], bbox_max[3];
  int render_vertex_count;   /* the render mesh's (qv_instance_render), 0 when the model has none */
  int render_triangle_count;
} qv_model_info;

/* How a model is held in memory. Fill with qv_model_config_init(). */
typedef struct qv_model_config {
  int coefficient_precision; /* 64 (default): the baked coefficients exactly; 32: the packed quartic
                                in float32 (at r = 30: 0.97 MB instead of 1.43 without the groups'
                                layout, 1.62 instead of 2.67 with it), force and stiffness within
                                about 1e-7 relative (bench/README.md) */
  int group_layout;          /* 1: also lay the quartic coefficients out for qv_instances_step's groups
                                of 16 (crowds step 2.8x faster than one by one at r = 30 on a Zen 5;
                                2.67 MB instead of 1.43 at r = 30 in float64, 38 MB instead of 20 at
                                r = 60); 0: not, and qv_instances_step steps this model's instances
                                one by one; -1 (default): 1 up to r = 64, else 0 */
} qv_model_config;
QV_API void qv_model_config_init(qv_model_config* config);

/* Loads a .qvr file or a .qvr image in memory (copied; the caller may free it afterwards).
   `config` and `allocator` may be NULL for the defaults and the C heap (an allocator given needs both
   functions). On failure *model is NULL and, when `message` is not NULL, it receives a NUL-terminated
   description (file, section, offset, what is wrong; or which argument is invalid), truncated to
   `message_size` bytes. Beyond the format, an energy that falls without bound along a mode's own axis
   is refused too (QV_ERROR_FORMAT; formats/model/QVR.md, Validation). */
QV_API qv_result qv_model_load_file(const char* path, const qv_model_config* config, const qv_allocator* allocator,
                                    qv_model** model, char* message, size_t message_size);
QV_API qv_result qv_model_load_memory(const void* data, size_t size, const qv_model_config* config,
                                      const qv_allocator* allocator, qv_model** model, char* message,
                                      size_t message_size);
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

/* ---- Simulation -------------------------------------------------------------------------
   A qv_instance steps one object: M q'' + C q' + R(q) = f in the model's r reduced coordinates
   (M = I: the basis is mass-orthonormal), with Rayleigh damping C = alpha I + beta K(q).
   Instances share their model read-only; each may run on its own thread. qv_instance_step()
   allocates nothing, takes no lock, throws nothing, and is deterministic: the same calls in the
   same order give bit-identical states. */

typedef enum qv_integrator {
  QV_INTEGRATOR_IMPLICIT_NEWMARK = 0, /* beta = 1/4, gamma = 1/2 (Barbic & James 2005); unconditionally stable */
  QV_INTEGRATOR_BACKWARD_EULER = 1,   /* implicit, first order, numerically damped */
  QV_INTEGRATOR_CENTRAL_DIFFERENCES = 2, /* explicit; stable below qv_instance_stable_time_step() */
  QV_INTEGRATOR_COUNT
} qv_integrator;

typedef enum qv_elasticity {
  QV_ELASTICITY_STVK = 0,          /* the baked St.Venant-Kirchhoff polynomial R(q) */
  QV_ELASTICITY_LINEAR = 1,        /* linear modal dynamics R(q) = K(0) q in the same subspace (small strains) */
  QV_ELASTICITY_MODAL_WARPING = 2, /* modal warping (Choi & Ko 2005): linear dynamics, each vertex's displacement
                                      rotated by its local rotation, forces rotated into the local frames; needs a
                                      model with modal rotations */
  QV_ELASTICITY_COUNT
} qv_elasticity;

/* How an implicit step (Newmark, backward Euler) solves for the end of the step. */
typedef enum qv_solver {
  QV_SOLVER_MINIMIZE = 0, /* default. The step is the minimum of its incremental potential (inertia + elastic
                             energy + the loads' potentials + a damping potential): Newton on a Hessian shifted to
                             positive definite where compression makes it indefinite, backtracking on the potential,
                             until the gradient is below newton_tolerance or after newton_iterations; the total
                             energy never grows within a step (what the integrator would add is taken out of the
                             velocity). No bounded load can make it run away: it resets only on non-finite input.
                             Its iterates stay within max_displacement (a box through |q|, or |q| at the step's
                             start where that is farther), so that a model whose energy falls without bound (a
                             damaged or crafted file the loader's checks let through) stays finite too.
                             Rayleigh damping C = alpha I + beta K(q) uses K at the step's start (lagged, shifted to
                             positive definite where compression made it indefinite), so it damps a bent object as
                             the Newton iterations do. Costs about 2x a fixed Newton step where one iteration
                             converges, 3x where two do (bench/README.md). */
  QV_SOLVER_NEWTON = 1,   /* Barbic & James 2005: exactly newton_iterations Newton iterations on the equations of
                             motion, the first linearised at the step's start (as Vega's implicit Newmark), no line
                             search, C = alpha I + beta K(q): the fastest while the strains stay moderate. The total
                             energy is held to the same budget as the minimiser's, one step late: what a step ended
                             with beyond it is taken out at the next step's start (E at the end is evaluated there
                             anyway), from the velocity or, where the position alone holds more, by drawing the state
                             back toward the last step's start; so a state handed out may hold more than its budget
                             for one step, and after a draw-back the next 60 steps are held to it at their ends at
                             one more evaluation of the energy each (released undamped from a 180-degree twist at one iteration, a sliver
                             beam's energy exceeded that at the release at 6-7 of 480 step ends, at most 8.2 times
                             it; 84% of them, and a runaway, in runtime 0.11). Where strains are large (stiff
                             springs, large twists, long time steps, sudden loads and releases) the iterations can
                             diverge: a step whose system is not positive definite, or whose end may move a vertex
                             farther than max_displacement (or, under implicit Newmark, with soft contacts in its
                             solve: qv_instance_config.soft_contacts), is taken by the minimising solver instead (at
                             most 8 iterations; qv_step_report.minimized), so it does not reset on finite input
                             either. (Linearised at the guess the last acceleration gives instead, one or two
                             iterations a step threw a 3 m bar of 1 MPa resting on rigid contacts off at thousands
                             of m/s: runtime 0.11 and before.) */
  QV_SOLVER_COUNT
} qv_solver;

/* Each choice has one short name, for options and files ("newmark", "euler", "central"; "stvk", "linear",
   "warping"; "minimize", "newton"), and a description for menus; both NULL out of range. *_from_name sets *value
   and returns QV_OK, or returns QV_ERROR_INVALID_ARGUMENT for a name it does not know. */
QV_API const char* qv_integrator_name(qv_integrator integrator);
QV_API const char* qv_integrator_description(qv_integrator integrator);
QV_API qv_result qv_integrator_from_name(const char* name, qv_integrator* integrator);
QV_API const char* qv_elasticity_name(qv_elasticity elasticity);
QV_API const char* qv_elasticity_description(qv_elasticity elasticity);
QV_API qv_result qv_elasticity_from_name(const char* name, qv_elasticity* elasticity);
QV_API const char* qv_solver_name(qv_solver solver);
QV_API const char* qv_solver_description(qv_solver solver);
QV_API qv_result qv_solver_from_name(const char* name, qv_solver* solver);

typedef struct qv_instance_config {
  qv_integrator integrator;  /* default QV_INTEGRATOR_IMPLICIT_NEWMARK */
  double time_step;          /* s, >= QV_MIN_TIME_STEP; default: the model's suggested step */
  qv_solver solver;          /* implicit integrators; default QV_SOLVER_MINIMIZE */
  int newton_iterations;     /* >= 1: the most Newton iterations (QV_SOLVER_MINIMIZE, default 8), or exactly this many
                                (QV_SOLVER_NEWTON; Barbic & James use 1; a step the minimiser takes over: at most 8) */
  double newton_tolerance;   /* QV_SOLVER_MINIMIZE stops once |gradient| <= this x the step's force scale; default 1e-6 */
  double rayleigh_alpha;     /* 1/s, >= 0; default: the model's */
  double rayleigh_beta;      /* s, >= 0; default: the model's */
  int max_constraints;       /* penalty constraint slots (drag springs, pinned groups), 0..64; default 4 */
  double max_displacement;   /* m; a step that may move a vertex farther (a bound through |q|): QV_SOLVER_NEWTON takes it with the minimising
                                solver instead (so every step, at about 3x the cost, while a load holds the object
                                past it), whose iterates stay within it; central differences reset the instance;
                                default 100 x the model's diagonal */
  qv_elasticity elasticity;  /* default QV_ELASTICITY_STVK */
  int free_flight;           /* 1: the object flies in a moving frame (qv_rigid_state; needs has_rigid_body); default 0 */
  int max_contacts;          /* in flight: contact points solved per step, 0..4096; default 64. When more touch, each
                                touching patch keeps a subset spread over it (docs/architecture.md, Contact) */
  int soft_contacts;         /* in flight, stepped implicitly, not with modal warping: 1: contacts hold the deformed surface, and the contact solve
                                lets the deformation give way where it pushes (a soft object rests flat instead of sagging
                                through what holds it: docs/architecture.md, Contact); 0 (default): they hold the rigid
                                shape the frame carries, and the deformation only takes their forces. Under implicit
                                Newmark with QV_SOLVER_NEWTON, a step with such contacts in its solve (touching, or
                                within reach) is the minimiser's (qv_step_report.minimized): the trapezoidal rule's
                                fixed steps rang against them (a 3 m soft bar resting on the ground: vertices at
                                5-9 cm/s after 20 s) and, at one or two Newton iterations, threw the bar off. Backward
                                Euler's fixed steps rest there */
  int max_substeps;          /* in flight, 1..64: q's step is cut into substeps in which the body turns at most 0.75 rad (a
                                faster spin made the step's minimisation non-convex, and the energy rose up to 7-fold:
                                docs/architecture.md, Free flight), at most this many (past that, a substep turns
                                farther); 1: never cut. Each costs about a step. Default 16 */
} qv_instance_config;

/* Defaults for `model` (pass NULL for model-independent defaults). */
QV_API void qv_instance_config_init(qv_instance_config* config, const qv_model* model);

typedef struct qv_instance qv_instance;

/* Bytes (and alignment, 64) of the block an instance lives in, for qv_instance_create_in_place. */
QV_API size_t qv_instance_memory_requirements(const qv_model* model, const qv_instance_config* config);
/* Creates an instance in memory from `allocator` (NULL: the C heap), or in a caller-owned block of
   at least qv_instance_memory_requirements() bytes, 64-byte aligned (destroy frees nothing then). */
QV_API qv_result qv_instance_create(const qv_model* model, const qv_instance_config* config,
                                    const qv_allocator* allocator, qv_instance** instance);
QV_API qv_result qv_instance_create_in_place(const qv_model* model, const qv_instance_config* config, void* memory,
                                             size_t size, qv_instance** instance);
QV_API void qv_instance_destroy(qv_instance* instance);

typedef enum qv_step_status {
  QV_STEP_OK = 0,
  QV_STEP_INDEFINITE = 1, /* the minimising solver (by choice, or taking a QV_SOLVER_NEWTON step) met a system matrix
                             made indefinite by large compression, and shifted it to positive definite */
  QV_STEP_RESET = 2       /* the state became non-finite (non-finite loads or state set), or central differences
                             may have moved a vertex farther than max_displacement: the instance was reset to rest */
} qv_step_status;

/* Advances one time step under the loads set so far; per-step loads are then cleared. */
QV_API qv_step_status qv_instance_step(qv_instance* instance);

/* What the last step did (all zero before the first). */
typedef struct qv_step_report {
  int newton_iterations;   /* Newton iterations taken (0 for central differences) */
  int line_search_cuts;    /* QV_SOLVER_MINIMIZE: step halvings in all */
  int converged;           /* QV_SOLVER_MINIMIZE: 1 when the gradient met newton_tolerance */
  double gradient;         /* QV_SOLVER_MINIMIZE: |gradient| / force scale at the end */
  int held_back;           /* 1 when the end position alone held more energy than the step may end with, so it was
                              drawn back toward the start (the velocity keeps what is left); QV_SOLVER_NEWTON: the
                              last step's end, at this step's start, or, after such a draw-back, this step's end */
  double energy_removed;   /* kinetic energy (J) the step took out so as not to add energy (QV_SOLVER_NEWTON: at its
                              start, of what the step before ended with beyond its budget, and, after a draw-back
                              (held_back), at its end) */
  int minimized;           /* QV_SOLVER_NEWTON: 1 when the minimising solver took the step (the Newton system was not
                              positive definite, the step may have moved a vertex past max_displacement, or, under
                              implicit Newmark, soft contacts were in its solve); the fields above then describe its step */
  int substeps;            /* the substeps q's step took (qv_instance_config.max_substeps); the fields above sum or
                              combine theirs */
} qv_step_report;
QV_API void qv_instance_last_step(const qv_instance* instance, qv_step_report* report);

/* Many instances of one model in one call: each is stepped as qv_instance_step() would step it,
   but implicit Newmark St.Venant-Kirchhoff instances are evaluated QV_GROUP_SIZE (16) at a time:
   each coefficient is read once for the 16 and multiplies their states at once (SIMD across
   instances), and their Newton matrices are factorised 16 at a time (not in free flight, where
   they depend on the state),
   on models loaded with the groups' layout (qv_model_config.group_layout; without it each
   instance steps as alone).
   QV_SOLVER_NEWTON steps go in groups of 16 (the evaluation and matrix at the state: the whole of
   a one-iteration step but its substitution); QV_SOLVER_MINIMIZE steps run up to 16 in lock step,
   sharing every evaluation of their iterations and line searches (the energy budget's rare
   draw-back evaluates alone). The sums run in another
   order than one instance's, so states agree with qv_instance_step() to rounding, not bit for bit
   (docs/architecture.md, "Many instances"), except from a QV_SOLVER_NEWTON step the minimiser took
   over (qv_step_report.minimized) on: such a step amplifies rounding, and whether it is taken over
   can itself differ; they do not depend on the number of jobs when every
   instance is groupable. Do not pass instances that are in a qv_world: the world steps them.

   No allocation: `scratch` (64-byte aligned) holds qv_instances_step_scratch_size(model, jobs)
   bytes. No threads: with `jobs` not NULL the instances are cut into jobs->count contiguous ranges
   (on multiples of QV_GROUP_SIZE: more jobs than groups only idle), and jobs->run(jobs->user, job, job_data, jobs->count) must call
   job(job_data, i) once for each i, on any threads, and return when all have run. NULL: one job on the calling thread. The same
   instance may not appear twice. statuses[i] (when not NULL) receives instances[i]'s status.
   QV_ERROR_INVALID_ARGUMENT: a null pointer, instances of different models, too small a scratch. */
#define QV_GROUP_SIZE 16
typedef void (*qv_job_function)(void* job_data, int job_index);
typedef struct qv_job_runner {
  int count; /* >= 1: how many jobs (e.g. worker threads) */
  void (*run)(void* user, qv_job_function job, void* job_data, int job_count);
  void* user;
} qv_job_runner;
QV_API size_t qv_instances_step_scratch_size(const qv_model* model, int jobs);
QV_API qv_result qv_instances_step(qv_instance* const* instances, int count, const qv_job_runner* jobs,
                                   void* scratch, size_t scratch_size, qv_step_status* statuses);

/* Loads. Per-step (cleared by each step): a force on one vertex (N), a reduced force (r values).
   Persistent: gravity (m/s^2), and penalty constraints pulling vertices toward targets with a
   spring of `stiffness` (N/m) per vertex: one vertex dragged by the mouse, or a group held at
   positions that a caller moves and rotates (drag and twist). Targets and stiffness must be finite. */
QV_API qv_result qv_instance_add_vertex_force(qv_instance* instance, int vertex, const double force[3]);
QV_API qv_result qv_instance_add_reduced_force(qv_instance* instance, const double* force);
QV_API void qv_instance_set_gravity(qv_instance* instance, const double acceleration[3]);
QV_API qv_result qv_instance_set_constraint(qv_instance* instance, int slot, const int* vertices, int count,
                                            const double* targets, double stiffness);
QV_API void qv_instance_clear_constraint(qv_instance* instance, int slot);

/* State (r values each; any pointer may be NULL: that part is left as it is, except that a NULL
   acceleration with a new q or velocity is replaced by the one the equations of motion give there
   under the persistent loads; a new state starts a new energy budget), reset to rest, and energies (J). */
QV_API void qv_instance_get_state(const qv_instance* instance, double* q, double* velocity, double* acceleration);
QV_API void qv_instance_set_state(qv_instance* instance, const double* q, const double* velocity,
                                  const double* acceleration);

/* Everything that evolves (q, velocity, acceleration, the solver's energy budget and its damping
   stiffness, r (r + 1) / 2 values, the last step's per-step forces, which the next step's budget
   compares with, and in flight the pose, the momenta, the pose a reset goes to and the last step's
   contacts, from which the next step's start) as an opaque block, for rewinding, replays and save games: restoring a snapshot and
   repeating the same calls repeats the same bits, in contact too. qv_instance_snapshot_size() is the most
   a snapshot takes (max_contacts contacts held); saving returns the bytes this one took, which is all
   there is to keep (qv_instance_contacts reports the contacts it holds after restoring). Restoring takes
   any size from those bytes to the most, and checks that the snapshot came from a model of the same r,
   that its values are finite (but for the last step's forces, where a step that reset may leave one
   that is not), that a flying instance's orientation is not zero, that its damping stiffness is
   positive definite, and that its contacts are ones a step could have ended with (their vertices in the
   model, their colliders among those set now (set the colliders first), unit normals, normal impulses
   not negative, in the order a step leaves them): QV_ERROR_INVALID_ARGUMENT otherwise, the instance
   unchanged. In a world, the world holds its instances' contacts and whether
   they sleep: rewind it with qv_world_save_snapshot. Restoring also restores whether a persistent load
   had changed since that step, so set loads after restoring, as the calls being repeated would. The
   layout may change between runtime versions (a flying instance's did after 0.13 and 0.14): the checks
   refuse most others'. Saving uses the instance's scratch (QV_SOLVER_NEWTON: it evaluates the state),
   so save one instance from one thread at a time. */
QV_API size_t qv_instance_snapshot_size(const qv_instance* instance);
QV_API size_t qv_instance_save_snapshot(const qv_instance* instance, void* snapshot);
QV_API qv_result qv_instance_restore_snapshot(qv_instance* instance, const void* snapshot, size_t size);
QV_API void qv_instance_reset(qv_instance* instance);
QV_API void qv_instance_energies(const qv_instance* instance, double* kinetic, double* elastic);

/* ---- Free flight ----
   An instance with config.free_flight = 1 is a rigid frame, its centre of mass at `position` turned by
   `orientation`, carrying the deformation q (docs/architecture.md, "Free flight"). Every position and normal it
   hands out is in the world; vertex forces and gravity are world vectors and act on the frame and on q alike
   (a uniform field such as gravity moves the frame only). Without external forces its linear and angular
   momentum stay what they were to round-off. It starts where the model was baked, at rest; a reset returns it
   to the last state set here, at rest. Penalty constraints (qv_instance_set_constraint) are for pinned models. */
typedef struct qv_rigid_state {
  double position[3];          /* m, world position of the centre of mass (at creation: the baked one) */
  double orientation[4];       /* unit quaternion w, x, y, z turning the baked model into the world (normalised on set) */
  double linear_velocity[3];   /* m/s, of the centre of mass */
  double angular_velocity[3];  /* rad/s, world axes */
} qv_rigid_state;
/* QV_ERROR_INVALID_ARGUMENT for an instance that does not fly or non-finite values. Setting it is a new state
   (qv_instance_set_state with the same q and velocity): the acceleration becomes the one the new spin gives. */
QV_API qv_result qv_instance_get_rigid_state(const qv_instance* instance, qv_rigid_state* state);
QV_API qv_result qv_instance_set_rigid_state(qv_instance* instance, const qv_rigid_state* state);

/* Colliders: static or moved by the game between steps. A flying instance touches them with its surface
   vertices: each step, velocity-level impulses on its frame (restitution, Coulomb friction; stiff at any time
   step), found and solved on the rigid shape it carries (or, with soft_contacts, on its deformed surface,
   which gives way where they push), and the same forces on its deformation. At rest a
   vertex sinks by a slop of 1e-3 of the model's diagonal, the contacts' slight softness and its own
   deformation: 1.5 mm (2.4e-3 of the diagonal) on tests/runtime/contact_test.cpp's soft bar at 1/60 s.
   Nothing moving faster than the step can see tunnels: a vertex is caught while its frame's (and the
   collider's) motion can reach the collider within the step; a collider thinner than the spacing of the
   object's surface vertices can pass between them. */
typedef enum qv_collider_type {
  QV_COLLIDER_PLANE = 0,   /* data: nx, ny, nz, d: the points with n . x = d; the object stays on the side n points to */
  QV_COLLIDER_SPHERE = 1,  /* data: x, y, z, radius */
  QV_COLLIDER_BOX = 2,     /* data: cx, cy, cz, hx, hy, hz: centre and half extents, turned by `rotation` */
  QV_COLLIDER_CAPSULE = 3, /* data: x0, y0, z0, x1, y1, z1, radius: the points within radius of the segment */
  QV_COLLIDER_MESH = 4     /* `mesh`, moved by data: x, y, z and turned by `rotation` about that point */
} qv_collider_type;

/* A closed triangle mesh for QV_COLLIDER_MESH: its signed distance comes from the closest point (a bounding
   volume hierarchy) and the angle-weighted pseudo-normal there, exact for any closed mesh, convex or not.
   Built once (checked: finite, indices in range, no degenerate triangle, every edge shared by exactly two
   triangles running it in opposite directions; an inward-facing mesh is turned outward); immutable and
   shared by any number of colliders and threads. On a bad mesh QV_ERROR_FORMAT with what and where. */
typedef struct qv_triangle_mesh qv_triangle_mesh;
QV_API qv_result qv_triangle_mesh_create(const double* positions, int vertex_count, const int* triangles,
                                         int triangle_count, const qv_allocator* allocator, qv_triangle_mesh** mesh,
                                         char* message, size_t message_size);
QV_API void qv_triangle_mesh_destroy(qv_triangle_mesh* mesh);

typedef struct qv_collider {
  qv_collider_type type;
  double data[8];      /* m, as the type says; unused entries must be finite */
  double friction;     /* Coulomb coefficient mu, >= 0 */
  double restitution;  /* 0 (no bounce) .. 1 (elastic) */
  double rotation[3];  /* box and mesh: rotation vector (axis times angle, rad) about the centre; 0: none */
  /* A kinematic collider (one the game moves): the velocity of its reference point (a sphere's, box's or
     mesh's centre data[0..2], a capsule's first end, a plane's point nearest the origin) and its angular
     velocity about it, m/s and rad/s; the contacts see the surface move (a platform lifts, a belt carries).
     The game moves the collider itself between steps. */
  double velocity[3];
  double angular_velocity[3];
  const qv_triangle_mesh* mesh; /* QV_COLLIDER_MESH: kept by pointer, alive while the collider is used */
} qv_collider;
/* The colliders a flying instance meets, `count` of them at `colliders`: kept by pointer (the caller keeps
   the array alive and may change it between steps; each step reads it). QV_ERROR_INVALID_ARGUMENT for an
   instance that does not fly or an invalid collider (the colliders are left as they were). NULL, 0: none. */
QV_API qv_result qv_instance_set_colliders(qv_instance* instance, const qv_collider* colliders, int count);
/* The last step's contacts: where, the collider's outward normal, and the impulse it gave (N s, world). */
typedef struct qv_contact {
  int vertex;
  int collider;       /* index into the colliders array; -1 when it touched another instance */
  double point[3];    /* m, the vertex at the step's start */
  double normal[3];
  double impulse[3];  /* over the step, on this object: divide by the time step for the force */
  double depth;       /* the deformed vertex's signed distance at the step's start: negative where it penetrated
                         (contacts are found and solved on the rigid shape the frame carries, unless soft_contacts;
                         the deformation takes their forces and may sink a vertex by its own displacement) */
  int instance;       /* in a world: the index (qv_world_add's order) of the instance whose vertex it is */
  int other;          /* in a world: the index of the instance it touched, -1 for a collider */
} qv_contact;
/* Copies up to `capacity` of the last step's contacts into `contacts`; returns how many there were. */
QV_API int qv_instance_contacts(const qv_instance* instance, qv_contact* contacts, int capacity);

/* A world: flying instances (of one or more models) that touch each other and the world's colliders. Each
   world step steps every instance once: their frames' forces, then one contact solve over all of them (an
   instance's surface vertices against the colliders and against the rest surface of every other instance
   near it, carried by its frame; impulses on both frames and both deformations), then their moves and
   deformations. Contact between instances is vertex against surface: an edge crossing an edge with no
   vertex inside is not seen. The world keeps the instances by pointer; an instance's own colliders
   (qv_instance_set_colliders) are not used in a world. No allocation in the step; deterministic.
   Sleeping: instances that could touch each other in a step (and those that could touch those) form a group;
   a group all of whose instances have been slower than sleep_speed for sleep_time (and at least a step),
   with no moving collider (one with a velocity) within reach, falls asleep: its instances keep their pose
   and deformation, at rest, and are not stepped, and have no contacts from the next step on, until
   something wakes them: an awake instance or a moving collider coming within reach, or the caller giving
   one of them a force, other gravity, a state, a pose (qv_instance_add_vertex_force, ..._set_rigid_state,
   ...) or qv_instance_wake, which wakes the whole group it fell asleep with, or qv_world_set_colliders
   (which wakes all). A collider moved without a velocity wakes nothing: call qv_world_set_colliders again. */
typedef struct qv_world qv_world;
typedef struct qv_world_config {
  int max_instances;  /* default 64 */
  int max_contacts;   /* all the world's contacts in a step (more: each patch keeps a spread subset); default 4096 */
  double friction;    /* between instances: Coulomb mu, default 0.5 */
  double restitution; /* between instances: 0..1, default 0 */
  double sleep_speed; /* m/s, >= 0: an instance is still while its frame's surface speed and its deformation's RMS
                         speed over the step together stay below this; 0: never sleep; default 0.02 */
  double sleep_time;  /* s, >= 0: how long a group must be still to fall asleep; default 0.5 */
} qv_world_config;
QV_API void qv_world_config_init(qv_world_config* config);
QV_API qv_result qv_world_create(const qv_world_config* config, const qv_allocator* allocator, qv_world** world);
QV_API void qv_world_destroy(qv_world* world);
/* Adds a flying instance (QV_ERROR_INVALID_ARGUMENT: not flying, already in, its time step differs from the
   others', or the world is full); returns its index through `index` when not NULL. */
QV_API qv_result qv_world_add(qv_world* world, qv_instance* instance, int* index);
/* Takes an instance out (QV_ERROR_INVALID_ARGUMENT: not in it), as a game despawns an object; remove an
   instance before destroying it. The instances after it move down an index (as the last step's contacts
   name them); the others' contacts carry on; the instances it fell asleep with wake (what rested on it
   falls). It keeps its state and pose, awake, and may be stepped alone or added again. A world snapshot
   saved before names the instances as they were: restore it only into the same instances in the same order. */
QV_API qv_result qv_world_remove(qv_world* world, qv_instance* instance);
/* The world's colliders, kept by pointer as qv_instance_set_colliders keeps them; wakes every instance. */
QV_API qv_result qv_world_set_colliders(qv_world* world, const qv_collider* colliders, int count);
/* Steps every instance once (asleep: none); returns how many reset (a blown-up state; never expected). */
QV_API int qv_world_step(qv_world* world);
/* More cores for a world's steps (the runtime starts no threads): each instance's own parts of a step (its
   frame's forces, and after the contact solve its move and deformation) run as jobs->count jobs over
   contiguous ranges of the instances, and the contact solve's sweeps as jobs over its islands (the bodies
   its contacts join, which share nothing), as qv_instances_step runs its jobs (jobs->run must call
   job(job_data, i) once for each i, on any threads, and return when all have run); finding the contacts
   stays on the calling thread. The same bits whatever the jobs. Kept by pointer; NULL (the default): all
   on the calling thread. QV_ERROR_INVALID_ARGUMENT: count < 1 or no run function. */
QV_API qv_result qv_world_set_jobs(qv_world* world, const qv_job_runner* jobs);
/* Whether an instance is asleep in its world (0 outside a world), and waking it (with the group it slept with). */
QV_API int qv_instance_asleep(const qv_instance* instance);
QV_API void qv_instance_wake(qv_instance* instance);
/* The last world step's contacts, as qv_instance_contacts (instance and other say who touched whom; the
   impulse is on `instance`, its opposite on `other`). */
QV_API int qv_world_contacts(const qv_world* world, qv_contact* contacts, int capacity);
/* A world's snapshot: each instance's (as qv_instance_save_snapshot), whether it sleeps and with whom,
   and the last step's contacts between them all, for rewinding a scene (rollback, replays, save games):
   restoring it and repeating the same calls repeats the same bits. The colliders are the caller's:
   restore them too. Sizes, checks and threads as for an instance's snapshot; restoring also checks
   that the world holds as many instances as it did, and changes nothing where a check fails. */
QV_API size_t qv_world_snapshot_size(const qv_world* world);
QV_API size_t qv_world_save_snapshot(const qv_world* world, void* snapshot);
QV_API qv_result qv_world_restore_snapshot(qv_world* world, const void* snapshot, size_t size);

/* Largest stable time step of central differences at rest, s: 2 / (c + sqrt(c^2 + omega_max^2)) for
   the stiffest mode of K(0), whose Rayleigh damping c = rayleigh_alpha + rayleigh_beta omega_max^2
   is explicit (2 / omega_max undamped; stiffness-proportional damping can lower it tenfold). */
QV_API double qv_instance_stable_time_step(const qv_instance* instance);

/* Output into caller-owned buffers: deformed positions X + U q (3 floats per vertex; x + R (X - c + U q) in flight), of all
   vertices or of the listed ones; and area-weighted vertex normals of the surface, computed
   from `positions` of all vertices (3 floats per vertex; vertices off the surface get 0). */
QV_API void qv_instance_positions(const qv_instance* instance, float* positions);
QV_API qv_result qv_instance_positions_of(const qv_instance* instance, const int* vertices, int count, float* positions);
QV_API void qv_model_surface_normals(const qv_model* model, const float* positions, float* normals);

/* The render mesh, for a model baked with one (qv_model_info.render_vertex_count > 0; NULL otherwise):
   an artist's triangle mesh each of whose vertices a tet carries (formats/model/QVR.md, RENDER_MESH).
   Its rest positions (3 floats per vertex), triangles (3 indices each, counter-clockwise seen from
   outside), rest normals (3 floats: as baked, or area-weighted) and UVs (2 floats, NULL when it has none). */
QV_API const float* qv_model_render_rest_positions(const qv_model* model);
QV_API const unsigned* qv_model_render_triangles(const qv_model* model);
QV_API const float* qv_model_render_normals(const qv_model* model);
QV_API const float* qv_model_render_uvs(const qv_model* model);
/* Bytes of scratch qv_instance_render needs for instances of this model (0 without a render mesh). */
QV_API size_t qv_model_render_scratch_size(const qv_model* model);
/* The render mesh's deformed positions (3 floats per render vertex; in the world in flight) and, when
   `normals` is not NULL, its normals (the rest normals turned by their tet's deformation). `scratch`:
   qv_model_render_scratch_size() bytes, 16-byte aligned, one per thread. Allocates nothing.
   QV_ERROR_INVALID_ARGUMENT for a model without a render mesh or a null buffer. */
QV_API qv_result qv_instance_render(const qv_instance* instance, float* positions, float* normals, void* scratch);

#ifdef __cplusplus
}
#endif

#endif
