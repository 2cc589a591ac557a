#include "step_many.h"

#include "integrators/integrator.h"

namespace quiver::rt {

namespace {

constexpr int kLanes = ReducedPolynomial::kLanes;

// Whose step begins with a polynomial evaluation at newmarkGuess(): both Newmark solvers do.
bool groupable(const qv_instance& s) {
  return s.config.integrator == QV_INTEGRATOR_IMPLICIT_NEWMARK && s.config.elasticity == QV_ELASTICITY_STVK;
}

void beginOwnStep(qv_instance& s) {
  s.beginStep();
  if (s.flying()) s.solveOwnContacts();
}

void stepGroup(qv_instance* const* group, const int* index, int count, double* scratch, qv_step_status* statuses) {
  const double* at[kLanes] = {};
  double* force[kLanes] = {};
  double* stiffness[kLanes] = {};
  double energy[kLanes] = {};
  for (int l = 0; l < count; ++l) {
    qv_instance& s = *group[l];
    beginOwnStep(s);
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

void stepManyRange(qv_instance* const* instances, int first, int last, void* scratch, qv_step_status* statuses) {
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

} // namespace quiver::rt
