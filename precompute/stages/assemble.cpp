#include "precompute/stages/assemble.h"

#include <algorithm>

#include "common/mass_matrix.h"
#include "common/stvk_element.h"
#include "common/tet_elements.h"

namespace quiver {

namespace {

// Non-zeros per owned row, split into PETSc's diagonal block (columns this rank owns) and the rest.
void countNonZeros(const TetMesh& mesh, const DofLayout& layout, std::vector<PetscInt>& diagonal,
                   std::vector<PetscInt>& offDiagonal) {
  const int64_t lo = layout.rowStart(), hi = lo + layout.localDofs();
  std::vector<int> localIndex(mesh.vertexCount(), -1);
  for (size_t i = 0; i < layout.ownedVertices().size(); ++i) localIndex[layout.ownedVertices()[i]] = static_cast<int>(i);
  std::vector<std::vector<int>> neighbours(layout.ownedVertices().size());
  for (const Tet& t : mesh.tets)
    for (int a : t)
      if (localIndex[a] >= 0)
        for (int b : t)
          if (layout.dof(b, 0) >= 0) neighbours[localIndex[a]].push_back(b);
  diagonal.assign(layout.localDofs(), 0);
  offDiagonal.assign(layout.localDofs(), 0);
  for (size_t i = 0; i < neighbours.size(); ++i) {
    auto& list = neighbours[i];
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
    PetscInt in = 0, out = 0;
    for (int b : list) (layout.dof(b, 0) >= lo && layout.dof(b, 0) < hi ? in : out) += 3;
    for (int c = 0; c < 3; ++c) {
      diagonal[3 * i + c] = in;
      offDiagonal[3 * i + c] = out;
    }
  }
}

PetscMat createMatrix(const DofLayout& layout, const std::vector<PetscInt>& diagonal,
                      const std::vector<PetscInt>& offDiagonal) {
  PetscMat A;
  QV_PETSC(MatCreateAIJ(layout.comm(), layout.localDofs(), layout.localDofs(), layout.globalDofs(),
                        layout.globalDofs(), 0, diagonal.data(), 0, offDiagonal.data(), A.out()));
  QV_PETSC(MatSetOption(A, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_TRUE));
  QV_PETSC(MatSetOption(A, MAT_NO_OFF_PROC_ENTRIES, PETSC_TRUE));  // each rank adds its own rows only
  QV_PETSC(MatSetOption(A, MAT_SYMMETRIC, PETSC_TRUE));
  QV_PETSC(MatSetOption(A, MAT_SYMMETRY_ETERNAL, PETSC_TRUE));
  return A;
}

} // namespace

AssembledSystem assembleSystem(const TetMesh& mesh, const std::vector<Material>& perTet, const DofLayout& layout) {
  std::vector<PetscInt> diagonal, offDiagonal;
  countNonZeros(mesh, layout, diagonal, offDiagonal);
  AssembledSystem sys{createMatrix(layout, diagonal, offDiagonal), createMatrix(layout, diagonal, offDiagonal)};

  const TetElements elements = computeTetElements(mesh);
  const Eigen::Matrix3d atRest = Eigen::Matrix3d::Zero();  // displacement gradient at rest
  PetscInt rows[12], columns[12];
  Eigen::Matrix<double, 12, 12, Eigen::RowMajor> Ke, Me;
  for (int t = 0; t < mesh.tetCount(); ++t) {
    const Tet& tet = mesh.tets[t];
    if (!layout.ownsRowOf(tet)) continue;
    for (int a = 0; a < 4; ++a)
      for (int c = 0; c < 3; ++c) {
        columns[3 * a + c] = static_cast<PetscInt>(layout.dof(tet[a], c));
        rows[3 * a + c] = layout.owns(columns[3 * a + c]) ? columns[3 * a + c] : -1;
      }
    const Material& m = perTet[t];
    const double V = elements.volume[t];
    Ke = stvkElementTangent(atRest, elements.gradients[t], V, m.lambda(), m.mu());
    Me.setZero();
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b)
        Me.block<3, 3>(3 * a, 3 * b).diagonal().setConstant(m.density * V * consistentMassWeight(a, b));
    // Negative indices are ignored by PETSc: fixed DOFs (that is the elimination) and, as rows,
    // the DOFs other ranks own (they add this tet themselves).
    QV_PETSC(MatSetValues(sys.stiffness, 12, rows, 12, columns, Ke.data(), ADD_VALUES));
    QV_PETSC(MatSetValues(sys.mass, 12, rows, 12, columns, Me.data(), ADD_VALUES));
  }
  for (Mat A : {sys.stiffness.get(), sys.mass.get()}) {
    QV_PETSC(MatAssemblyBegin(A, MAT_FINAL_ASSEMBLY));
    QV_PETSC(MatAssemblyEnd(A, MAT_FINAL_ASSEMBLY));
  }
  return sys;
}

} // namespace quiver
