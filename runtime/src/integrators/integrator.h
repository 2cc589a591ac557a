#pragma once
// Time integrators. Each lives in its own file as one function that advances an instance by one
// step; adding one means its file, a value of qv_integrator and a row of kIntegrators.
#include "../instance.h"
#include "incremental_potential.h"

namespace quiver::rt {

using StepFunction = qv_step_status (*)(qv_instance&);

struct IntegratorEntry {
  qv_integrator id;
  const char* name;
  const char* description;
  StepFunction step;
};
// Indexed by qv_integrator: the one table of names.
extern const IntegratorEntry kIntegrators[QV_INTEGRATOR_COUNT];

struct SolverEntry {
  qv_solver id;
  const char* name;
  const char* description;
};
extern const SolverEntry kSolvers[QV_SOLVER_COUNT];

qv_step_status stepImplicitNewmark(qv_instance& s);
// Its fixed Newton step in two parts, so that a group solves its members' first systems together
// (step_many.cpp): up to the first solve, its right-hand side in s.work.correction (false where the
// step went to the minimiser instead, with its status in `status`); then the rest, the first
// system already solved (`solved`: the correction in s.work.correction) or not.
struct NewmarkNewton {
  double budget;
  const double* J;
};
bool beginNewmarkNewton(qv_instance& s, NewmarkNewton& step, qv_step_status& status);
qv_step_status endNewmarkNewton(qv_instance& s, const NewmarkNewton& step, bool solved);
// Its minimising solver's step in parts (a group runs the middle, step_many.h): qt, v0 and the
// guess; then, after the minimisation, the end of the step as its minimum, with Newmark's own
// acceleration a' = 4/h^2 (x - qt) (the equations of motion's at convergence; bounded by the
// potential when the iteration cap comes first), or none where the step was held back.
StepPredictor beginNewmarkMinimization(qv_instance& s);
qv_step_status endNewmarkMinimization(qv_instance& s, const StepPredictor& p, qv_step_status status);
// Implicit Newmark's first guess at the end of the step, q + h v + h^2/2 a (the last acceleration
// kept): where the minimiser starts, and where a group evaluates it (step_many.h).
inline double newmarkGuess(const qv_instance& s, int i) {
  const double h = s.config.time_step;
  return s.q[i] + h * s.v[i] + 0.5 * h * h * s.a[i];
}
// Whether implicit Newmark's fixed Newton step is the minimiser's from its start: soft contacts were
// in its solve (implicit_newmark.cpp says why). A group (step_many.cpp) leaves such a step out of
// its evaluation.
inline bool newmarkStepMinimized(const qv_instance& s) { return s.softContact; }
// Implicit Newmark's parameters (the trapezoidal rule), and the scales of its fixed Newton step's
// system (I + c1 C + c2 (K + J)) x = rhs.
constexpr double kNewmarkBeta = 0.25, kNewmarkGamma = 0.5;
inline void newmarkNewtonScales(const qv_instance& s, double& c1, double& c2) {
  const double h = s.config.time_step;
  c1 = kNewmarkGamma * h;
  c2 = kNewmarkBeta * h * h;
}
qv_step_status stepBackwardEuler(qv_instance& s);
qv_step_status stepCentralDifferences(qv_instance& s);

} // namespace quiver::rt
