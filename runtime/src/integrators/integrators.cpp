#include "integrator.h"

namespace quiver::rt {

const IntegratorEntry kIntegrators[QV_INTEGRATOR_COUNT] = {
    {QV_INTEGRATOR_IMPLICIT_NEWMARK, "newmark", "implicit Newmark", stepImplicitNewmark},
    {QV_INTEGRATOR_BACKWARD_EULER, "euler", "backward Euler", stepBackwardEuler},
    {QV_INTEGRATOR_CENTRAL_DIFFERENCES, "central", "central differences", stepCentralDifferences},
};

} // namespace quiver::rt
