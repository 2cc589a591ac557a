#include "step_many.h"

#include <algorithm>

#include "cholesky_lanes.h"
#include "integrators/integrator.h"

namespace quiver::rt {

namespace {

constexpr int kLanes = ReducedPolynomial::kLanes;

size_t pairs(int r) { return static_cast<size_t>(r) * (r + 1) / 2; }

// Whose step begins with a polynomial evaluation at newmarkGuess(): both Newmark solvers do.
bool groupable(const qv_instance& s) {
  return s.config.integrator == QV_INTEGRATOR_IMPLICIT_NEWMARK && s.config.elasticity == QV_ELASTICITY_STVK;
}

// Whose first Newton matrix the group factorises too: a fixed Newton step's, whose state forces'
// Jacobian is the constraints' constant one (in flight it depends on q).
bool factorisedInGroup(const qv_instance& s) {
  return s.config.integrator == QV_INTEGRATOR_IMPLICIT_NEWMARK && s.config.solver == QV_SOLVER_NEWTON && !s.flying();
}

// Copies the upper triangles of the group's packed lanes (evaluateLanes()'s layout) into the members'
// row-major r x r matrices, row by row: a row's lanes are one short contiguous run.
void unpackUpper(const double* lanes, int r, int count, double* const* out) {
  for (int a = 0; a < r; ++a) {
    const double* row = lanes + (packedUpperIndex(r, a, a) - static_cast<size_t>(a)) * kLanes;
    for (int l = 0; l < count; ++l)
      for (int b = a; b < r; ++b) out[l][a * r + b] = row[b * kLanes + l];
  }
}

// The group's first Newton matrices I + c1 C + c2 (K + J), the terms solveNewton() (dynamics.cpp)
// builds, factorised together in `A` (K in, as evaluateLanes() leaves it) and each one's
// factor handed to its step in `system`. Lanes without such a step factorise the identity.
void factoriseGroup(qv_instance* const* group, int count, double* A) {
  const int r = group[0]->r;
  double scaleK[kLanes], scaleJ[kLanes], diagonal[kLanes], c1[kLanes], c2[kLanes];
  const double* J[kLanes];
  bool constrained = false;
  for (int l = 0; l < kLanes; ++l) {
    const qv_instance& s = *group[l < count ? l : 0];
    const bool factorised = l < count && factorisedInGroup(s);
    newmarkNewtonScales(s, c1[l], c2[l]);
    scaleK[l] = factorised ? c1[l] * s.config.rayleigh_beta + c2[l] : 0.0;
    scaleJ[l] = factorised ? c2[l] : 0.0;
    diagonal[l] = factorised ? 1.0 + c1[l] * s.config.rayleigh_alpha : 1.0;
    J[l] = s.loads.constraintK;  // zero while no constraint is active
    constrained = constrained || (factorised && s.loads.constrained);
  }
  for (int a = 0, p = 0; a < r; ++a)
    for (int b = a; b < r; ++b, ++p) {
      double* x = A + p * kLanes;
      for (int l = 0; l < kLanes; ++l) x[l] = scaleK[l] * x[l] + (a == b ? diagonal[l] : 0.0);
      if (constrained)
        for (int l = 0; l < kLanes; ++l) x[l] += scaleJ[l] * J[l][a * r + b];
    }
  bool ok[kLanes];
  choleskyFactorLanes(A, r, ok);
  double* system[kLanes];
  for (int l = 0; l < count; ++l) system[l] = group[l]->work.system;
  unpackUpper(A, r, count, system);
  for (int l = 0; l < count; ++l) {
    qv_instance& s = *group[l];
    // Not positive definite: the step's own solve decides (pivoting LU).
    s.work.presetFactored = ok[l] && factorisedInGroup(s);
    s.work.presetC1 = c1[l];
    s.work.presetC2 = c2[l];
  }
}

void stepGroup(qv_instance* const* group, const int* index, int count, double* scratch, qv_step_status* statuses) {
  const int r = group[0]->r;
  double* stiffnessLanes = scratch;  // [pair][lane]
  double* polynomialScratch = scratch + pairs(r) * kLanes;
  const double* at[kLanes] = {};
  double* force[kLanes] = {};
  double* stiffness[kLanes] = {};
  double energy[kLanes] = {};
  bool factorise = false;
  for (int l = 0; l < count; ++l) {
    qv_instance& s = *group[l];
    s.beginOwnStep();
    for (int i = 0; i < s.r; ++i) s.work.presetAt[i] = newmarkGuess(s, i);
    at[l] = s.work.presetAt;
    force[l] = s.work.presetForce;
    stiffness[l] = s.work.stiffness;
    factorise = factorise || factorisedInGroup(s);
  }
  group[0]->model->polynomial.evaluateLanes(at, count, energy, force, stiffnessLanes, polynomialScratch);
  unpackUpper(stiffnessLanes, r, count, stiffness);
  for (int l = 0; l < count; ++l)  // the lower half, within each member's own matrix
    for (int a = 0; a < r; ++a)
      for (int b = a + 1; b < r; ++b) stiffness[l][b * r + a] = stiffness[l][a * r + b];
  if (factorise) factoriseGroup(group, count, stiffnessLanes);
  for (int l = 0; l < count; ++l) {
    qv_instance& s = *group[l];
    s.work.presetEnergy = energy[l];
    s.work.presetValid = true;
    const qv_step_status status = s.finishStep();
    if (statuses) statuses[index[l]] = status;
  }
}

} // namespace

size_t stepManyScratchPerJob(const qv_model& model) {
  const int r = model.info.r;
  const size_t doubles = pairs(r) * kLanes + ReducedPolynomial::laneScratchSize(r);
  return (doubles * sizeof(double) + 63) & ~size_t(63);
}

namespace {

// Steps instances [first, last): groups of the groupable ones in order, the others alone.
void stepRange(qv_instance* const* instances, int first, int last, void* scratch, qv_step_status* statuses) {
  qv_instance* group[kLanes];
  int index[kLanes];
  int count = 0;
  auto flush = [&] {
    if (count > 1) {
      stepGroup(group, index, count, static_cast<double*>(scratch), statuses);
    } else if (count == 1) {  // alone, the one-state evaluation is the faster
      const qv_step_status status = group[0]->step();
      if (statuses) statuses[index[0]] = status;
    }
    count = 0;
  };
  for (int i = first; i < last; ++i) {
    qv_instance& s = *instances[i];
    if (!groupable(s)) {
      const qv_step_status status = s.step();
      if (statuses) statuses[i] = status;
      continue;
    }
    group[count] = &s;
    index[count++] = i;
    if (count == kLanes) flush();
  }
  flush();
}

struct Work {
  qv_instance* const* instances;
  int count;
  int jobs;
  char* scratch;
  qv_step_status* statuses;
};

void runJob(void* data, int job) {
  const Work& w = *static_cast<const Work*>(data);
  if (job < 0 || job >= w.jobs) return;
  // Cut on multiples of a group, so that a crowd of groupable instances forms the same groups, and
  // so the same bits, whatever the number of jobs.
  const long long groups = (w.count + kLanes - 1) / kLanes;
  const auto bound = [&](int j) { return static_cast<int>(std::min<long long>(w.count, groups * j / w.jobs * kLanes)); };
  const size_t perJob = stepManyScratchPerJob(*w.instances[0]->model);
  stepRange(w.instances, bound(job), bound(job + 1), w.scratch + perJob * job, w.statuses);
}

} // namespace

void stepMany(qv_instance* const* instances, int count, const qv_job_runner* runner, void* scratch,
              qv_step_status* statuses) {
  Work work{instances, count, runner ? runner->count : 1, static_cast<char*>(scratch), statuses};
  if (runner)
    runner->run(runner->user, runJob, &work, work.jobs);
  else
    runJob(&work, 0);
}

} // namespace quiver::rt
