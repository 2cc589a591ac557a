#include "step_many.h"

#include <algorithm>
#include <cstring>

#include "cholesky_lanes.h"
#include "dense_solve.h"
#include "dynamics.h"
#include "jobs.h"
#include "simd_dispatch.h"
#include "integrators/integrator.h"

namespace quiver::rt {

namespace {

constexpr int kLanes = ReducedPolynomial::kLanes;
static_assert(kLanes == QV_GROUP_SIZE, "quiver.h tells callers the group size");

size_t pairs(int r) { return static_cast<size_t>(r) * (r + 1) / 2; }

// A job's scratch (stepManyScratchPerJob()): the group's K packed by lane (evaluateLanes()); the
// same, each member's packed on its own, which members read until their steps end
// (qv_instance::work.stiffnessPacked); the group's factors (its systems from K, factorised); then
// what the evaluation uses, free again once it has run.
double* memberStiffness(double* scratch, int r) { return scratch + pairs(r) * kLanes; }
double* factorLanes(double* scratch, int r) { return scratch + 2 * pairs(r) * kLanes; }
double* afterFactors(double* scratch, int r) { return scratch + 3 * pairs(r) * kLanes; }

// Whose step begins with a polynomial evaluation (implicit Newmark's: the minimiser's at
// newmarkGuess(), the fixed Newton step's at q), on a model laid out for groups
// (qv_model_config.group_layout).
bool groupable(const qv_instance& s) {
  return s.config.integrator == QV_INTEGRATOR_IMPLICIT_NEWMARK && s.config.elasticity == QV_ELASTICITY_STVK &&
         s.model->polynomial.groups();
}

// Whether the group factorises the matrices a member's solver will solve with: not in flight, where
// the state forces' Jacobian depends on q (elsewhere it is the constraints' constant one).
bool factorisedInGroup(const qv_instance& s) { return !s.flying(); }

// Factorises together the members' matrices with `scales` (SystemScales, instance.h) at the
// point just evaluated, from `K`, the group's K (as evaluateLanes() leaves it), into `A`, and hands
// each member its lane of A (presetFactor). Lanes not factorised (factorisedInGroup()) factorise
// the identity.
QV_HOT void factoriseGroup(qv_instance* const* group, int count, const SystemScales* scales, const double* K,
                           double* A) {
  const int r = group[0]->r;
  SystemScales lane[kLanes];
  const double* J[kLanes];
  const double* D[kLanes];
  bool any = false, constrained = false, damped = false;
  for (int l = 0; l < kLanes; ++l) {
    const qv_instance& s = *group[l < count ? l : 0];
    const bool factorised = l < count && factorisedInGroup(s);
    lane[l] = factorised ? scales[l] : SystemScales{0.0, 0.0, 0.0, 1.0};
    J[l] = s.loads.constraintK;  // zero while no constraint is active
    D[l] = s.dampingStiffness;
    any = any || factorised;
    constrained = constrained || (factorised && s.loads.constrained);
    damped = damped || lane[l].dampingStiffness != 0;
  }
  for (int l = 0; l < count; ++l) group[l]->work.presetFactor = LaneFactor{};
  if (!any) return;
  // The terms in fillSystem()'s order (dynamics.cpp).
  for (int a = 0, p = 0; a < r; ++a)
    for (int b = a; b < r; ++b, ++p) {
      double* x = A + p * kLanes;
      for (int l = 0; l < kLanes; ++l) x[l] = K[p * kLanes + l] * lane[l].stiffness;
      if (constrained)
        for (int l = 0; l < kLanes; ++l) x[l] += lane[l].stateJacobian * J[l][a * r + b];
      if (damped)
        for (int l = 0; l < kLanes; ++l) x[l] += lane[l].dampingStiffness * D[l][a * r + b];
      if (a == b)
        for (int l = 0; l < kLanes; ++l) x[l] += lane[l].identity;
    }
  bool ok[kLanes];
  choleskyFactorLanes(A, r, ok);
  for (int l = 0; l < count; ++l) {
    qv_instance& s = *group[l];
    // Not positive definite: the solver's own factorisation decides (the minimiser shifts it).
    s.work.presetFactor = ok[l] && factorisedInGroup(s) ? LaneFactor{A, r, l} : LaneFactor{};
    s.work.presetScales = lane[l];
  }
}

// Evaluates the members' polynomials together at their presetAt points and leaves each one's
// preset for its step's next evaluation there: R(q), E(q) and K(q) (packed, in the scratch);
// returns the group's K packed by lane (evaluateLanes()) at the start of `scratch`.
QV_HOT double* evaluateTogether(qv_instance* const* members, int count, double* scratch) {
  const int r = members[0]->r;
  double* stiffnessLanes = scratch;  // [pair][lane]
  const double* at[kLanes] = {};
  double* force[kLanes] = {};
  double energy[kLanes] = {};
  for (int l = 0; l < count; ++l) {
    at[l] = members[l]->work.presetAt;
    force[l] = members[l]->work.presetForce;
  }
  members[0]->model->polynomial.evaluateLanes(at, count, energy, force, stiffnessLanes, afterFactors(scratch, r));
  // Each member's K on its own, in one pass over the lanes.
  const size_t P = pairs(r);
  double* own = memberStiffness(scratch, r);
  for (size_t p = 0; p < P; ++p)
    for (int l = 0; l < count; ++l) own[l * P + p] = stiffnessLanes[p * kLanes + l];
  for (int l = 0; l < count; ++l) {
    members[l]->work.presetStiffness = own + l * P;
    members[l]->work.presetEnergy = energy[l];
    members[l]->work.presetValid = true;
    members[l]->work.presetDefinite = false;
  }
  return stiffnessLanes;
}

// Which of the group's K (as evaluateTogether() leaves them, in `K`) are positive definite, by
// their Cholesky factorisations together in `scratch` (the pairs times kLanes doubles): a
// minimising step that ends at its point damps the next with K itself then (dampWithStiffness()),
// which alone factorised K once more, a ninth of a crowd's frame at r = 30. The factorisation's
// operations are choleskyFactor()'s, built for the same instruction set (both QV_HOT), so the
// verdict is that of the one it saves.
void markDefinite(qv_instance* const* members, int count, const double* K, double* scratch) {
  const int r = members[0]->r;
  std::memcpy(scratch, K, sizeof(double) * pairs(r) * kLanes);
  bool ok[kLanes];
  choleskyFactorLanes(scratch, r, ok);
  for (int l = 0; l < count; ++l) members[l]->work.presetDefinite = ok[l];
}

// The members' systems solved together where they take lanes of one group factor (a null factor:
// not solved here): the right-hand sides in their s.work.correction, four lanes at a time
// interleaved in `B` (r times four doubles, 32-byte aligned), every substitution's operation one
// vector across them, each lane's those of its own solve (each member alone read its lane with a
// stride of kLanes, one latency after another). The solutions replace the right-hand sides.
QV_HOT void solveTogether(qv_instance* const* members, const LaneFactor* factors, int count, double* B) {
  constexpr int W = LanesFactor::kWidth;
  const int r = members[0]->r;
  const double* A = nullptr;
  double* rhs[kLanes] = {};  // by the factor's lane
  for (int l = 0; l < count; ++l)
    if (factors[l].A) A = factors[l].A, rhs[factors[l].lane] = members[l]->work.correction;
  for (int part = 0; A && part < kLanes / W; ++part) {
    double* const* x = rhs + W * part;
    if (std::none_of(x, x + W, [](const double* lane) { return lane != nullptr; })) continue;
    // Lanes no member solves in hold zeros; their results are dropped.
    for (int k = 0; k < r; ++k)
      for (int l = 0; l < W; ++l) B[k * W + l] = x[l] ? x[l][k] : 0.0;
    choleskySubstitute(LanesFactor{A, r, part}, reinterpret_cast<LanesFactor::Value*>(B), r);
    for (int l = 0; l < W; ++l)
      if (x[l])
        for (int k = 0; k < r; ++k) x[l][k] = B[k * W + l];
  }
}

// Fixed Newton steps, up to kLanes: one evaluation each, at the state (fixed_newton.h), and its
// Newton matrix, both together; then every step up to its first solve, the solves together, and
// every step's rest. Members whose step is the minimiser's (newmarkStepMinimized()) are not
// evaluated here; a member spinning fast takes its step in substeps (finishStep()), alone.
void stepNewtonGroup(qv_instance* const* group, const int* index, int count, double* scratch,
                     qv_step_status* statuses) {
  qv_instance* fixed[kLanes];
  SystemScales scales[kLanes];
  int fixedCount = 0;
  bool alone[kLanes];
  for (int l = 0; l < count; ++l) {
    qv_instance& s = *group[l];
    s.beginOwnStep();
    alone[l] = s.deformationSubsteps() > 1;
    if (alone[l]) {
      const qv_step_status status = s.finishStep();
      if (statuses) statuses[index[l]] = status;
      continue;
    }
    if (newmarkStepMinimized(s)) continue;
    std::memcpy(s.work.presetAt, s.q, sizeof(double) * s.r);
    double c1, c2;
    newmarkNewtonScales(s, c1, c2);
    scales[fixedCount] = newtonSystem(s, c1, c2);
    fixed[fixedCount++] = &s;
  }
  if (fixedCount > 0)
    factoriseGroup(fixed, fixedCount, scales, evaluateTogether(fixed, fixedCount, scratch), factorLanes(scratch, group[0]->r));
  NewmarkNewton step[kLanes];
  qv_step_status status[kLanes];
  bool going[kLanes];
  LaneFactor factor[kLanes];  // where the first system is solved together: as solveNewton() takes it
  for (int l = 0; l < count; ++l) {
    qv_instance& s = *group[l];
    going[l] = false, factor[l] = LaneFactor{};
    if (alone[l]) continue;
    s.moveFrame();  // as finishStep() would
    going[l] = beginNewmarkNewton(s, step[l], status[l]);
    double c1, c2;
    newmarkNewtonScales(s, c1, c2);
    factor[l] = going[l] ? takePresetFactor(s, newtonSystem(s, c1, c2)) : LaneFactor{};
  }
  // The evaluation's scratch is free again: the right-hand sides go there.
  solveTogether(group, factor, count, afterFactors(scratch, group[0]->r));
  for (int l = 0; l < count; ++l) {
    qv_instance& s = *group[l];
    if (alone[l]) continue;
    if (going[l]) status[l] = endNewmarkNewton(s, step[l], factor[l].A != nullptr);
    status[l] = s.endStep(status[l]);
    if (statuses) statuses[index[l]] = status[l];
  }
}

// Minimising steps in lock step: up to kLanes under way, each round evaluates every one's pending
// point together and resumes them; a finished step's lane goes to the next instance that
// `next(i)` names (-1: none). Every evaluation of these steps is a group's, so each one's bits do
// not depend on which others share its rounds.
template <class Next>
void stepMinimizingTogether(qv_instance* const* instances, Next next, double* scratch, qv_step_status* statuses) {
  qv_instance* member[kLanes];
  int index[kLanes];
  MinimizeTask task[kLanes];
  StepPredictor predictor[kLanes];
  int active = 0, cursor = next(-1);
  // Takes the next instance into `lane`; false when none is left. One spinning fast takes its step
  // in substeps (finishStep()), alone, and the next is taken instead.
  const auto admit = [&](int lane) {
    for (; cursor >= 0; cursor = next(cursor)) {
      qv_instance& s = *instances[cursor];
      s.beginOwnStep();
      if (s.deformationSubsteps() == 1) break;
      const qv_step_status status = s.finishStep();
      if (statuses) statuses[cursor] = status;
    }
    if (cursor < 0) return false;
    qv_instance& s = *instances[cursor];
    s.moveFrame();
    predictor[lane] = beginNewmarkMinimization(s);
    task[lane].begin(s, predictor[lane]);
    member[lane] = &s;
    index[lane] = cursor;
    cursor = next(cursor);
    return true;
  };
  while (active < kLanes && admit(active)) ++active;
  while (active > 0) {
    for (int l = 0; l < active; ++l)
      std::memcpy(member[l]->work.presetAt, task[l].pending(), sizeof(double) * member[l]->r);
    // Each point's Newton matrix too, for the direction the step takes from it if it goes on.
    SystemScales scales[kLanes];
    for (int l = 0; l < active; ++l) scales[l] = minimizerSystem(*member[l], predictor[l]);
    double* K = evaluateTogether(member, active, scratch);
    // The evaluation's scratch is free again.
    markDefinite(member, active, K, afterFactors(scratch, member[0]->r));
    factoriseGroup(member, active, scales, K, factorLanes(scratch, member[0]->r));
    for (int l = 0; l < active; ++l) task[l].resume();
    // The Newton directions the steps take from there, solved together.
    LaneFactor factor[kLanes];
    for (int l = 0; l < active; ++l) factor[l] = task[l].awaitedSolve();
    solveTogether(member, factor, active, afterFactors(scratch, member[0]->r));
    for (int l = 0; l < active; ++l)
      if (factor[l].A) task[l].solved(), task[l].resume();
    for (int l = 0; l < active;) {
      if (task[l].pending()) {
        ++l;
        continue;
      }
      qv_instance& s = *member[l];
      const qv_step_status status = s.endStep(endNewmarkMinimization(s, predictor[l], task[l].status()));
      if (statuses) statuses[index[l]] = status;
      if (admit(l)) {
        ++l;
      } else {  // the last lane's step moves here
        --active;
        member[l] = member[active], index[l] = index[active], task[l] = task[active], predictor[l] = predictor[active];
      }
    }
  }
}

} // namespace

size_t stepManyScratchPerJob(const qv_model& model) {
  if (!model.polynomial.groups()) return 64;  // nothing is stepped in groups: one line, never read
  const int r = model.info.r;
  const size_t doubles = 3 * pairs(r) * kLanes + ReducedPolynomial::laneScratchSize(r);
  return (doubles * sizeof(double) + 63) & ~size_t(63);
}

namespace {

bool minimizing(const qv_instance& s) { return s.config.solver == QV_SOLVER_MINIMIZE; }

// Steps instances [first, last). The groupable ones are stepped together: fixed Newton steps in
// groups of kLanes in order, minimising steps in lock step; the others alone. When the range's
// groupable instances number one more than a multiple of kLanes, the last of them is stepped alone
// (for a lone instance the one-state evaluation is the faster); ranges are cut on multiples of
// kLanes instances, so in a crowd of groupable instances that is the same instance whatever the jobs.
void stepRange(qv_instance* const* instances, int first, int last, double* scratch, qv_step_status* statuses) {
  int groupableCount = 0, lone = -1;
  for (int i = first; i < last; ++i)
    if (groupable(*instances[i]) && groupableCount++ % kLanes == 0) lone = i;
  if (groupableCount % kLanes != 1) lone = -1;
  qv_instance* group[kLanes];
  int index[kLanes];
  int count = 0;
  for (int i = first; i < last; ++i) {
    qv_instance& s = *instances[i];
    if (!groupable(s) || i == lone) {
      const qv_step_status status = s.step();
      if (statuses) statuses[i] = status;
    } else if (!minimizing(s)) {
      group[count] = &s;
      index[count++] = i;
      if (count == kLanes) stepNewtonGroup(group, index, count, scratch, statuses), count = 0;
    }
  }
  if (count > 0) stepNewtonGroup(group, index, count, scratch, statuses);
  const auto next = [&](int i) {
    for (i = i < first ? first : i + 1; i < last; ++i)
      if (i != lone && groupable(*instances[i]) && minimizing(*instances[i])) return i;
    return -1;
  };
  stepMinimizingTogether(instances, next, scratch, statuses);
}

} // namespace

void stepMany(qv_instance* const* instances, int count, const qv_job_runner* runner, void* scratch,
              qv_step_status* statuses) {
  const int jobs = runner ? runner->count : 1;
  // Cut on multiples of a group, so that a crowd of groupable instances forms the same groups, and
  // so the same bits, whatever the number of jobs.
  const long long groups = (count + kLanes - 1) / kLanes;
  const auto bound = [&](int j) { return static_cast<int>(std::min<long long>(count, groups * j / jobs * kLanes)); };
  const size_t perJob = stepManyScratchPerJob(*instances[0]->model);
  runJobs(runner, jobs, [&](int job) {
    stepRange(instances, bound(job), bound(job + 1), reinterpret_cast<double*>(static_cast<char*>(scratch) + perJob * job),
              statuses);
  });
}

} // namespace quiver::rt
