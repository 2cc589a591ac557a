#include "step_many.h"

#include <algorithm>

#include "integrators/integrator.h"

namespace quiver::rt {

namespace {

constexpr int kLanes = ReducedPolynomial::kLanes;

// Whose step begins with a polynomial evaluation at newmarkGuess(): both Newmark solvers do.
bool groupable(const qv_instance& s) {
  return s.config.integrator == QV_INTEGRATOR_IMPLICIT_NEWMARK && s.config.elasticity == QV_ELASTICITY_STVK;
}

void stepGroup(qv_instance* const* group, const int* index, int count, double* scratch, qv_step_status* statuses) {
  const double* at[kLanes] = {};
  double* force[kLanes] = {};
  double* stiffness[kLanes] = {};
  double energy[kLanes] = {};
  for (int l = 0; l < count; ++l) {
    qv_instance& s = *group[l];
    s.beginOwnStep();
    for (int i = 0; i < s.r; ++i) s.work.presetAt[i] = newmarkGuess(s, i);
    at[l] = s.work.presetAt;
    force[l] = s.work.presetForce;
    stiffness[l] = s.work.stiffness;
  }
  group[0]->model->polynomial.evaluateLanes(at, count, energy, force, stiffness, scratch);
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
  return (ReducedPolynomial::laneScratchSize(model.info.r) * sizeof(double) + 63) & ~size_t(63);
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
