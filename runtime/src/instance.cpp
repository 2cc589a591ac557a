// qv_instance: one simulated object stepping the reduced equations M q'' + C q' + R(q) = f.
#include <cmath>
#include <cstring>
#include <new>

#include "block_carver.h"
#include "dense_solve.h"
#include "formats/model/modal_warping.h"
#include "quiver/quiver.h"

namespace {

using quiver::rt::BlockCarver;

double basisEntry(const qv_model* m, size_t row, size_t j) {
  const size_t r = static_cast<size_t>(m->info.r);
  return m->basis32 ? static_cast<double>(m->basis32[row * r + j]) : m->basis64[row * r + j];
}

// Vertex v's linear displacement U_v q and, with modal rotations, its rotation w_v = Psi_v q.
void vertexLinear(const qv_model* m, int v, const double* q, double d[3], double w[3]) {
  const size_t r = static_cast<size_t>(m->info.r);
  for (int c = 0; c < 3; ++c) {
    const size_t row = 3 * static_cast<size_t>(v) + c;
    double du = 0, dw = 0;
    for (size_t j = 0; j < r; ++j) {
      du += basisEntry(m, row, j) * q[j];
      if (w) dw += m->rotations[row * r + j] * q[j];
    }
    d[c] = du;
    if (w) w[c] = dw;
  }
}

} // namespace

struct qv_instance {
  const qv_model* model;
  qv_allocator allocator;
  bool ownsMemory;
  qv_instance_config config;
  int r;
  double maxQ;             // |q|_inf beyond which the state counts as blown up
  double stableStep;
  double gravity[3];
  double *q, *v, *a;       // state
  double *stepForce;       // reduced external force of this step only
  double *gravityForce;    // G g
  double *constraintK, *constraintB;  // sum over active slots of k U_v^T U_v and k U_v^T (target - X_v)
  double *slotK, *slotB;   // per slot
  int* slotActive;
  // scratch
  double *force, *stiffness, *system, *rhs, *trialQ, *trialV, *next, *polyScratch;
  double* rhsBackup;       // solve(): the right-hand side kept for the LU retry
  double* restStiffness;   // K(0), for linear modal dynamics
  int* pivot;

  template <class Carve>
  void carve(Carve& c, int maxConstraints) {
    const size_t rr = static_cast<size_t>(r) * r;
    q = c.template take<double>(r);
    v = c.template take<double>(r);
    a = c.template take<double>(r);
    stepForce = c.template take<double>(r);
    gravityForce = c.template take<double>(r);
    constraintK = c.template take<double>(rr);
    constraintB = c.template take<double>(r);
    slotK = c.template take<double>(rr * maxConstraints);
    slotB = c.template take<double>(static_cast<size_t>(r) * maxConstraints);
    slotActive = c.template take<int>(maxConstraints);
    force = c.template take<double>(r);
    stiffness = c.template take<double>(rr);
    system = c.template take<double>(rr);
    rhs = c.template take<double>(r);
    rhsBackup = c.template take<double>(r);
    trialQ = c.template take<double>(r);
    trialV = c.template take<double>(r);
    next = c.template take<double>(r);
    pivot = c.template take<int>(r);
    polyScratch = c.template take<double>(quiver::rt::ReducedPolynomial::scratchSize(r));
    restStiffness = c.template take<double>(rr);
  }

  // Elastic force and stiffness at `at` (StVK, or K(0) q when linear), plus the penalty
  // constraints: R + Kc q - bc, K + Kc.
  void evaluate(const double* at, double* energy) {
    if (config.linear || config.warping) {
      std::memcpy(stiffness, restStiffness, sizeof(double) * r * r);
      for (int i = 0; i < r; ++i) {
        double s = 0;
        for (int j = 0; j < r; ++j) s += restStiffness[i * r + j] * at[j];
        force[i] = s;
      }
    } else {
      model->polynomial.evaluate(at, energy, force, stiffness, polyScratch);
    }
    for (int i = 0; i < r; ++i) {
      double s = -constraintB[i];
      for (int j = 0; j < r; ++j) s += constraintK[i * r + j] * at[j];
      force[i] += s;
    }
  }

  // system = I + c1 C + c2 (K + Kc), with C = alpha I + beta K (elastic part only).
  void fillSystem(double c1, double c2) {
    const double alpha = config.rayleigh_alpha, beta = config.rayleigh_beta;
    for (int i = 0; i < r; ++i)
      for (int j = 0; j < r; ++j)
        system[i * r + j] = (c1 * beta + c2) * stiffness[i * r + j] + c2 * constraintK[i * r + j] +
                            (i == j ? 1.0 + c1 * alpha : 0.0);
  }

  // Solves (I + c1 C + c2 (K + Kc)) x = rhs in place (rhs becomes x): Cholesky, or pivoting LU
  // when large compression has made the matrix indefinite.
  qv_step_status solve(double c1, double c2) {
    fillSystem(c1, c2);
    // The Cholesky attempt spoils `system` and `rhs`, so keep the right-hand side for a second try.
    std::memcpy(rhsBackup, rhs, sizeof(double) * r);
    if (quiver::rt::choleskySolve(system, rhs, r)) return QV_STEP_OK;
    std::memcpy(rhs, rhsBackup, sizeof(double) * r);
    fillSystem(c1, c2);
    return quiver::rt::luSolve(system, rhs, pivot, r) ? QV_STEP_INDEFINITE : QV_STEP_RESET;
  }

  // C v with C = alpha I + beta K, K the elastic stiffness last evaluated.
  double damping(int i, const double* vel) const {
    double s = config.rayleigh_alpha * vel[i];
    for (int j = 0; j < r; ++j) s += config.rayleigh_beta * stiffness[i * r + j] * vel[j];
    return s;
  }
  double external(int i) const { return stepForce[i] + gravityForce[i]; }

  qv_step_status newmark() {
    const double h = config.time_step, beta = 0.25, gamma = 0.5;
    std::memcpy(next, a, sizeof(double) * r);  // Newton starts from the last acceleration
    qv_step_status status = QV_STEP_OK;
    for (int it = 0; it < config.newton_iterations; ++it) {
      for (int i = 0; i < r; ++i) {
        trialQ[i] = q[i] + h * v[i] + h * h * ((0.5 - beta) * a[i] + beta * next[i]);
        trialV[i] = v[i] + h * ((1 - gamma) * a[i] + gamma * next[i]);
      }
      evaluate(trialQ, nullptr);
      for (int i = 0; i < r; ++i) rhs[i] = -(next[i] + damping(i, trialV) + force[i] - external(i));
      const qv_step_status s = solve(gamma * h, beta * h * h);
      if (s == QV_STEP_RESET) return s;
      if (s == QV_STEP_INDEFINITE) status = s;
      for (int i = 0; i < r; ++i) next[i] += rhs[i];
    }
    for (int i = 0; i < r; ++i) {
      q[i] += h * v[i] + h * h * ((0.5 - beta) * a[i] + beta * next[i]);
      v[i] += h * ((1 - gamma) * a[i] + gamma * next[i]);
      a[i] = next[i];
    }
    return status;
  }

  qv_step_status backwardEuler() {
    const double h = config.time_step;
    std::memcpy(trialV, v, sizeof(double) * r);  // Newton on the new velocity, from the old one
    qv_step_status status = QV_STEP_OK;
    for (int it = 0; it < config.newton_iterations; ++it) {
      for (int i = 0; i < r; ++i) trialQ[i] = q[i] + h * trialV[i];
      evaluate(trialQ, nullptr);
      for (int i = 0; i < r; ++i) rhs[i] = -((trialV[i] - v[i]) + h * (damping(i, trialV) + force[i] - external(i)));
      const qv_step_status s = solve(h, h * h);
      if (s == QV_STEP_RESET) return s;
      if (s == QV_STEP_INDEFINITE) status = s;
      for (int i = 0; i < r; ++i) trialV[i] += rhs[i];
    }
    for (int i = 0; i < r; ++i) {
      a[i] = (trialV[i] - v[i]) / h;
      v[i] = trialV[i];
      q[i] += h * v[i];
    }
    return status;
  }

  // Velocity Verlet; damping uses the predicted velocity, so it stays explicit.
  qv_step_status centralDifferences() {
    const double h = config.time_step;
    for (int i = 0; i < r; ++i) q[i] += h * v[i] + 0.5 * h * h * a[i];
    evaluate(q, nullptr);
    for (int i = 0; i < r; ++i) trialV[i] = v[i] + h * a[i];
    for (int i = 0; i < r; ++i) next[i] = external(i) - force[i] - damping(i, trialV);
    for (int i = 0; i < r; ++i) {
      v[i] += 0.5 * h * (a[i] + next[i]);
      a[i] = next[i];
    }
    return QV_STEP_OK;
  }

  void rest() {
    std::memset(q, 0, sizeof(double) * r);
    std::memset(v, 0, sizeof(double) * r);
    std::memset(a, 0, sizeof(double) * r);
  }

  bool healthy() const {
    for (int i = 0; i < r; ++i)
      if (!(std::fabs(q[i]) <= maxQ) || !std::isfinite(v[i]) || !std::isfinite(a[i])) return false;
    return true;
  }

  void combineConstraints() {
    const size_t rr = static_cast<size_t>(r) * r;
    std::memset(constraintK, 0, sizeof(double) * rr);
    std::memset(constraintB, 0, sizeof(double) * r);
    for (int s = 0; s < config.max_constraints; ++s) {
      if (!slotActive[s]) continue;
      for (size_t k = 0; k < rr; ++k) constraintK[k] += slotK[s * rr + k];
      for (int i = 0; i < r; ++i) constraintB[i] += slotB[s * r + i];
    }
  }
};

namespace {

// Vertex v's displacement: U_v q, warped by its rotation under modal warping.
void vertexDisplacement(const qv_instance* s, int v, double u[3]) {
  if (!s->config.warping) {
    vertexLinear(s->model, v, s->q, u, nullptr);
    return;
  }
  double d[3], w[3];
  vertexLinear(s->model, v, s->q, d, w);
  quiver::warping::warpDisplacement(w, d, u);
}

bool validConfig(const qv_model* model, const qv_instance_config* c) {
  return model && c && (!c->warping || model->rotations) && c->time_step > 0 && std::isfinite(c->time_step) && c->newton_iterations >= 1 &&
         c->rayleigh_alpha >= 0 && c->rayleigh_beta >= 0 && c->max_constraints >= 0 && c->max_constraints <= 64 &&
         c->max_displacement > 0 &&
         (c->integrator == QV_INTEGRATOR_IMPLICIT_NEWMARK || c->integrator == QV_INTEGRATOR_BACKWARD_EULER ||
          c->integrator == QV_INTEGRATOR_CENTRAL_DIFFERENCES);
}

size_t instanceBytes(const qv_model* model, const qv_instance_config* config) {
  BlockCarver c(nullptr);
  c.take<qv_instance>(1);
  qv_instance probe{};
  probe.r = model->info.r;
  probe.carve(c, config->max_constraints);
  return c.size();
}

// Largest eigenvalue of the rest stiffness, by power iteration on K(0) (symmetric, PSD).
double largestRestEigenvalue(qv_instance* s) {
  const int r = s->r;
  std::memset(s->trialQ, 0, sizeof(double) * r);
  s->model->polynomial.evaluate(s->trialQ, nullptr, nullptr, s->stiffness, s->polyScratch);
  for (int i = 0; i < r; ++i) s->trialV[i] = 1.0 + 0.01 * i;
  double lambda = 0;
  for (int it = 0; it < 200; ++it) {
    double norm = 0;
    for (int i = 0; i < r; ++i) {
      double y = 0;
      for (int j = 0; j < r; ++j) y += s->stiffness[i * r + j] * s->trialV[j];
      s->next[i] = y;
      norm += y * y;
    }
    norm = std::sqrt(norm);
    if (!(norm > 0)) return 0;
    double dot = 0;
    for (int i = 0; i < r; ++i) dot += s->next[i] * s->trialV[i];
    double previous = 0;
    for (int i = 0; i < r; ++i) previous += s->trialV[i] * s->trialV[i];
    lambda = dot / previous;
    for (int i = 0; i < r; ++i) s->trialV[i] = s->next[i] / norm;
  }
  return lambda;
}

qv_instance* construct(const qv_model* model, const qv_instance_config* config, char* block) {
  BlockCarver c(block);
  qv_instance* s = new (c.take<qv_instance>(1)) qv_instance{};
  s->model = model;
  s->config = *config;
  s->r = model->info.r;
  s->carve(c, config->max_constraints);
  // ||u||_inf <= max_i ||U_i||_1 ||q||_inf: bound q so that no vertex can exceed max_displacement.
  double rowNorm = 0;
  for (size_t row = 0; row < 3 * static_cast<size_t>(model->info.vertex_count); ++row) {
    double sum = 0;
    for (int j = 0; j < s->r; ++j) sum += std::fabs(basisEntry(model, row, static_cast<size_t>(j)));
    rowNorm = std::fmax(rowNorm, sum);
  }
  s->maxQ = rowNorm > 0 ? config->max_displacement / rowNorm : config->max_displacement;
  const double lambdaMax = largestRestEigenvalue(s);  // also leaves K(0) in s->stiffness
  std::memcpy(s->restStiffness, s->stiffness, sizeof(double) * s->r * s->r);
  s->stableStep = lambdaMax > 0 ? 2.0 / std::sqrt(lambdaMax) : INFINITY;
  std::memset(s->stepForce, 0, sizeof(double) * s->r);
  std::memset(s->gravityForce, 0, sizeof(double) * s->r);
  std::memset(s->slotActive, 0, sizeof(int) * config->max_constraints);
  s->combineConstraints();
  s->rest();
  return s;
}

} // namespace

extern "C" {

void qv_instance_config_init(qv_instance_config* config, const qv_model* model) {
  if (!config) return;
  config->integrator = QV_INTEGRATOR_IMPLICIT_NEWMARK;
  config->time_step = model ? model->info.time_step : 1.0 / 60.0;
  config->newton_iterations = 1;
  config->rayleigh_alpha = model ? model->info.rayleigh_alpha : 0.0;
  config->rayleigh_beta = model ? model->info.rayleigh_beta : 0.0;
  config->max_constraints = 4;
  double diagonal = 1.0;
  if (model) {
    double d2 = 0;
    for (int k = 0; k < 3; ++k) d2 += (model->info.bbox_max[k] - model->info.bbox_min[k]) * (model->info.bbox_max[k] - model->info.bbox_min[k]);
    diagonal = std::sqrt(d2);
  }
  config->max_displacement = 100.0 * diagonal;
  config->linear = 0;
  config->warping = 0;
}

size_t qv_instance_memory_requirements(const qv_model* model, const qv_instance_config* config) {
  return validConfig(model, config) ? instanceBytes(model, config) : 0;
}

qv_result qv_instance_create_in_place(const qv_model* model, const qv_instance_config* config, void* memory,
                                      size_t size, qv_instance** instance) {
  if (!instance) return QV_ERROR_INVALID_ARGUMENT;
  *instance = nullptr;
  if (!validConfig(model, config) || !memory || reinterpret_cast<uintptr_t>(memory) % 64 != 0 ||
      size < instanceBytes(model, config))
    return QV_ERROR_INVALID_ARGUMENT;
  *instance = construct(model, config, static_cast<char*>(memory));
  (*instance)->ownsMemory = false;
  return QV_OK;
}

qv_result qv_instance_create(const qv_model* model, const qv_instance_config* config, const qv_allocator* allocator,
                             qv_instance** instance) {
  if (!instance) return QV_ERROR_INVALID_ARGUMENT;
  *instance = nullptr;
  if (!validConfig(model, config)) return QV_ERROR_INVALID_ARGUMENT;
  qv_allocator heap;
  qv_allocator_init(&heap);
  const qv_allocator& use = allocator ? *allocator : heap;
  char* block = static_cast<char*>(use.allocate(instanceBytes(model, config), 64, use.user));
  if (!block) return QV_ERROR_OUT_OF_MEMORY;
  *instance = construct(model, config, block);
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

qv_step_status qv_instance_step(qv_instance* s) {
  qv_step_status status = QV_STEP_OK;
  switch (s->config.integrator) {
    case QV_INTEGRATOR_IMPLICIT_NEWMARK: status = s->newmark(); break;
    case QV_INTEGRATOR_BACKWARD_EULER: status = s->backwardEuler(); break;
    case QV_INTEGRATOR_CENTRAL_DIFFERENCES: status = s->centralDifferences(); break;
  }
  std::memset(s->stepForce, 0, sizeof(double) * s->r);
  if (status == QV_STEP_RESET || !s->healthy()) {
    s->rest();
    return QV_STEP_RESET;
  }
  return status;
}

qv_result qv_instance_add_vertex_force(qv_instance* s, int vertex, const double force[3]) {
  if (!s || !force || vertex < 0 || vertex >= s->model->info.vertex_count) return QV_ERROR_INVALID_ARGUMENT;
  double local[3] = {force[0], force[1], force[2]};
  if (s->config.warping) {  // into the vertex's rotated frame: R(w)^T f, the rotation by -w
    double d[3], w[3];
    vertexLinear(s->model, vertex, s->q, d, w);
    const double back[3] = {-w[0], -w[1], -w[2]};
    quiver::warping::rotate(back, force, local);
  }
  for (int j = 0; j < s->r; ++j)
    for (int c = 0; c < 3; ++c) s->stepForce[j] += basisEntry(s->model, 3 * static_cast<size_t>(vertex) + c, j) * local[c];
  return QV_OK;
}

qv_result qv_instance_add_reduced_force(qv_instance* s, const double* force) {
  if (!s || !force) return QV_ERROR_INVALID_ARGUMENT;
  for (int j = 0; j < s->r; ++j) s->stepForce[j] += force[j];
  return QV_OK;
}

void qv_instance_set_gravity(qv_instance* s, const double g[3]) {
  if (!s || !g) return;
  const double* G = s->model->gravity;  // 3 x r: row a = U^T M e_a
  for (int j = 0; j < s->r; ++j) s->gravityForce[j] = G[j] * g[0] + G[s->r + j] * g[1] + G[2 * s->r + j] * g[2];
}

qv_result qv_instance_set_constraint(qv_instance* s, int slot, const int* vertices, int count, const double* targets,
                                     double stiffness) {
  if (!s || slot < 0 || slot >= s->config.max_constraints || count < 1 || !vertices || !targets || !(stiffness > 0))
    return QV_ERROR_INVALID_ARGUMENT;
  for (int k = 0; k < count; ++k)
    if (vertices[k] < 0 || vertices[k] >= s->model->info.vertex_count) return QV_ERROR_INVALID_ARGUMENT;
  const int r = s->r;
  double* K = s->slotK + static_cast<size_t>(slot) * r * r;
  double* b = s->slotB + static_cast<size_t>(slot) * r;
  std::memset(K, 0, sizeof(double) * r * r);
  std::memset(b, 0, sizeof(double) * r);
  // Penalty energy k/2 |X_v + U_v q - target_v|^2 per vertex: stiffness k U_v^T U_v, force k U_v^T (U_v q - (target - X_v)).
  for (int k = 0; k < count; ++k) {
    const size_t row = 3 * static_cast<size_t>(vertices[k]);
    for (int c = 0; c < 3; ++c) {
      const double gap = targets[3 * k + c] - s->model->rest[row + c];
      for (int i = 0; i < r; ++i) {
        const double ui = basisEntry(s->model, row + c, i);
        b[i] += stiffness * ui * gap;
        for (int j = 0; j < r; ++j) K[i * r + j] += stiffness * ui * basisEntry(s->model, row + c, j);
      }
    }
  }
  s->slotActive[slot] = 1;
  s->combineConstraints();
  return QV_OK;
}

void qv_instance_clear_constraint(qv_instance* s, int slot) {
  if (!s || slot < 0 || slot >= s->config.max_constraints) return;
  s->slotActive[slot] = 0;
  s->combineConstraints();
}

void qv_instance_get_state(const qv_instance* s, double* q, double* v, double* a) {
  if (!s) return;
  if (q) std::memcpy(q, s->q, sizeof(double) * s->r);
  if (v) std::memcpy(v, s->v, sizeof(double) * s->r);
  if (a) std::memcpy(a, s->a, sizeof(double) * s->r);
}

void qv_instance_set_state(qv_instance* s, const double* q, const double* v, const double* a) {
  if (!s) return;
  if (q) std::memcpy(s->q, q, sizeof(double) * s->r);
  if (v) std::memcpy(s->v, v, sizeof(double) * s->r);
  if (a) {
    std::memcpy(s->a, a, sizeof(double) * s->r);
  } else if (q || v) {
    // The acceleration the equations of motion give at the new state (persistent loads only), so
    // that the next implicit step starts consistent rather than injecting energy.
    s->evaluate(s->q, nullptr);
    for (int i = 0; i < s->r; ++i) s->a[i] = s->gravityForce[i] - s->force[i] - s->damping(i, s->v);
  }
}

void qv_instance_reset(qv_instance* s) {
  if (s) s->rest();
}

void qv_instance_energies(const qv_instance* s, double* kinetic, double* elastic) {
  if (!s) return;
  double k = 0;
  for (int i = 0; i < s->r; ++i) k += 0.5 * s->v[i] * s->v[i];
  if (kinetic) *kinetic = k;
  if (elastic && (s->config.linear || s->config.warping)) {
    double e = 0;
    for (int i = 0; i < s->r; ++i)
      for (int j = 0; j < s->r; ++j) e += 0.5 * s->q[i] * s->restStiffness[i * s->r + j] * s->q[j];
    *elastic = e;
  } else if (elastic) {
    s->model->polynomial.evaluate(s->q, elastic, nullptr, nullptr, s->polyScratch);
  }
}

double qv_instance_stable_time_step(const qv_instance* s) { return s ? s->stableStep : 0; }

void qv_instance_positions(const qv_instance* s, float* positions) {
  if (!s || !positions) return;
  if (!s->config.warping) {
    qv_model_displacements(s->model, s->q, positions);
    for (size_t i = 0; i < 3 * static_cast<size_t>(s->model->info.vertex_count); ++i)
      positions[i] = static_cast<float>(s->model->rest[i] + positions[i]);
    return;
  }
  for (int v = 0; v < s->model->info.vertex_count; ++v) {
    double u[3];
    vertexDisplacement(s, v, u);
    for (int c = 0; c < 3; ++c) positions[3 * v + c] = static_cast<float>(s->model->rest[3 * v + c] + u[c]);
  }
}

qv_result qv_instance_positions_of(const qv_instance* s, const int* vertices, int count, float* positions) {
  if (!s || !vertices || !positions || count < 0) return QV_ERROR_INVALID_ARGUMENT;
  for (int k = 0; k < count; ++k) {
    if (vertices[k] < 0 || vertices[k] >= s->model->info.vertex_count) return QV_ERROR_INVALID_ARGUMENT;
    double u[3];
    vertexDisplacement(s, vertices[k], u);
    for (int c = 0; c < 3; ++c) positions[3 * k + c] = static_cast<float>(s->model->rest[3 * vertices[k] + c] + u[c]);
  }
  return QV_OK;
}

void qv_model_surface_normals(const qv_model* m, const float* p, float* normals) {
  if (!m || !p || !normals) return;
  std::memset(normals, 0, sizeof(float) * 3 * static_cast<size_t>(m->info.vertex_count));
  for (int t = 0; t < m->info.triangle_count; ++t) {
    const unsigned* v = m->triangles + 3 * t;
    const float* a = p + 3 * v[0];
    const float* b = p + 3 * v[1];
    const float* c = p + 3 * v[2];
    const float e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    const float n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
    for (int k = 0; k < 3; ++k)
      for (int c2 = 0; c2 < 3; ++c2) normals[3 * v[k] + c2] += n[c2];  // area-weighted: |n| = 2 x area
  }
  for (int i = 0; i < m->info.vertex_count; ++i) {
    float* n = normals + 3 * i;
    const float len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (len > 0)
      for (int c = 0; c < 3; ++c) n[c] /= len;
  }
}

} // extern "C"
