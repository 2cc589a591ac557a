#pragma once
// Small rotations of displacement fields, for modal warping (Choi & Ko 2005): the rotation of a
// field u is w = (1/2) curl u, constant on a linear tet; each vertex gets the volume-weighted mean
// of its tets' rotations. For a basis U, the vertex rotations are linear in q: w_v = Psi_v q. The
// bake stores Psi in the .qvr; the runtime warps with it (quiver/modal_warping.h).
#include <Eigen/Core>

#include "common/tet_mesh.h"

namespace quiver {

// `fields`: 3n x r displacement fields (row 3v + c); returns the 3n x r rotations (row 3v + c
// is component c of vertex v's rotation vector, in radians per unit of the field).
Eigen::MatrixXd vertexRotations(const TetMesh& mesh, const Eigen::MatrixXd& fields);

} // namespace quiver
