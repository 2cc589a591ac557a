#pragma once
// Stage "assemble": the consistent mass M and the rest stiffness K(0) of the free DOFs as
// distributed PETSc matrices (MPIAIJ), preallocated exactly. Each rank adds the element matrices
// of every tet touching its rows, in tet order, into its own rows only (DofLayout::ownsRowOf): the
// same bits on every rank count and every run. Rows of fixed DOFs are never formed, which
// eliminates them.
#include <vector>

#include <petscmat.h>

#include "common/tet_mesh.h"
#include "precompute/dof_layout.h"
#include "precompute/petsc_handle.h"

namespace quiver {

using PetscMat = PetscHandle<Mat, MatDestroy>;

struct AssembledSystem {
  PetscMat stiffness;  // K(0), symmetric positive semi-definite (definite when anything is fixed)
  PetscMat mass;       // consistent mass, symmetric positive definite
};

// `perTet` one material per tet. Collective over layout.comm().
AssembledSystem assembleSystem(const TetMesh& mesh, const std::vector<Material>& perTet, const DofLayout& layout);

} // namespace quiver
