#pragma once
// The six rigid motions of a free (unconstrained) object: translations and infinitesimal
// rotations about the centroid, the null space of K. The modes stage deflates them and the
// derivatives stage projects them out.
#include <Eigen/Core>
#include <petscmat.h>

#include "common/tet_mesh.h"
#include "precompute/dof_layout.h"

namespace quiver {

// This rank's rows of the six rigid motions, M-orthonormal (R^T M R = I). Every vertex must be
// free. Collective.
Eigen::MatrixXd rigidModes(const TetMesh& mesh, Mat mass, const DofLayout& layout);

} // namespace quiver
