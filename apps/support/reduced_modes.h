#pragma once
// The linear vibration modes a reduced model holds: K~(0) x = lambda x in its r coordinates (the
// basis is mass-orthonormal, so M~ = I). They are the Rayleigh-Ritz approximations of the mesh's
// modes in span U: the baked modes themselves when U contains them, which is what the bake builds.
#include <Eigen/Core>

#include "quiver/quiver.h"

namespace quiver::app {

struct ReducedModes {
  Eigen::VectorXd eigenvalues;  // ascending, (rad/s)^2
  Eigen::MatrixXd vectors;      // r x r; column i: the reduced coordinates q of mode i, unit length
};

ReducedModes reducedModes(const qv_model* model);

// `q` scaled so that its largest vertex displacement |U_v q| is `amplitude` (zero stays zero).
Eigen::VectorXd withLargestDisplacement(const qv_model* model, const Eigen::VectorXd& q, double amplitude);

} // namespace quiver::app
