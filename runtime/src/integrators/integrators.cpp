#include "integrator.h"

namespace quiver::rt {

const IntegratorEntry kIntegrators[QV_INTEGRATOR_COUNT] = {
    {QV_INTEGRATOR_IMPLICIT_NEWMARK, "newmark", "implicit Newmark", stepImplicitNewmark},
    {QV_INTEGRATOR_BACKWARD_EULER, "euler", "backward Euler", stepBackwardEuler},
    {QV_INTEGRATOR_CENTRAL_DIFFERENCES, "central", "central differences", stepCentralDifferences},
};

const SolverEntry kSolvers[QV_SOLVER_COUNT] = {
    {QV_SOLVER_MINIMIZE, "minimize", "minimise potential"},
    {QV_SOLVER_NEWTON, "newton", "fixed Newton steps"},
};

} // namespace quiver::rt
