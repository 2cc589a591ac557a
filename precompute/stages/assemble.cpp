#include "precompute/stages/assemble.h"

#include <algorithm>

#include "common/mass_matrix.h"
#include "common/stvk_element.h"
#include "common/tet_elements.h"

namespace quiver {

namespace {

// This rank's rows in CSR form. An owned vertex's three rows share one pattern: the free vertices
// it shares a tet with, in DOF order (so each row's columns ascend), three columns each.
struct RowPattern {
  std::vector<int> localIndex;                // vertex -> its place among the owned vertices, or -1
  std::vector<std::vector<int64_t>> blocks;   // per owned vertex: neighbours' first DOFs, ascending
  std::vector<PetscInt> rowStart, columns;    // CSR over the local rows

  RowPattern(const TetMesh& mesh, const DofLayout& layout) : localIndex(mesh.vertexCount(), -1) {
    const auto& owned = layout.ownedVertices();
    for (size_t i = 0; i < owned.size(); ++i) localIndex[owned[i]] = static_cast<int>(i);
    blocks.resize(owned.size());
    for (const Tet& t : mesh.tets)
      for (int a : t)
        if (localIndex[a] >= 0)
          for (int b : t)
            if (layout.dof(b, 0) >= 0) blocks[localIndex[a]].push_back(layout.dof(b, 0));
    rowStart.assign(1, 0);
    for (auto& list : blocks) {
      std::sort(list.begin(), list.end());
      list.erase(std::unique(list.begin(), list.end()), list.end());
      for (int c = 0; c < 3; ++c) {
        for (int64_t first : list)
          for (int d = 0; d < 3; ++d) columns.push_back(static_cast<PetscInt>(first + d));
        rowStart.push_back(static_cast<PetscInt>(columns.size()));
      }
    }
  }

  // Where row (owned vertex a, component c) holds column (first DOF `first` of a neighbour) + d.
  size_t at(int a, int c, int64_t first, int d) const {
    const auto& list = blocks[localIndex[a]];
    const size_t block = std::lower_bound(list.begin(), list.end(), first) - list.begin();
    return static_cast<size_t>(rowStart[3 * localIndex[a] + c]) + 3 * block + d;
  }
};

// AIJ: sequential on one rank, as MatCreateAIJ makes it (MatCreateMPIAIJWithArrays would not).
PetscMat createMatrix(const DofLayout& layout, const RowPattern& pattern, const std::vector<double>& values) {
  PetscMat A;
  QV_PETSC(MatCreate(layout.comm(), A.out()));
  QV_PETSC(MatSetSizes(A, layout.localDofs(), layout.localDofs(), layout.globalDofs(), layout.globalDofs()));
  QV_PETSC(MatSetType(A, MATAIJ));
  // Each copies the arrays and assembles; the one not of A's type does nothing.
  QV_PETSC(MatSeqAIJSetPreallocationCSR(A, pattern.rowStart.data(), pattern.columns.data(), values.data()));
  QV_PETSC(MatMPIAIJSetPreallocationCSR(A, pattern.rowStart.data(), pattern.columns.data(), values.data()));
  QV_PETSC(MatSetOption(A, MAT_SYMMETRIC, PETSC_TRUE));
  QV_PETSC(MatSetOption(A, MAT_SYMMETRY_ETERNAL, PETSC_TRUE));
  return A;
}

} // namespace

// The element matrices are summed into CSR arrays here (PETSc's MatSetValues searched each of the
// 288 entries of a tet's two matrices into its rows: most of this stage), then handed over whole.
AssembledSystem assembleSystem(const TetMesh& mesh, const std::vector<Material>& perTet, const DofLayout& layout) {
  const RowPattern pattern(mesh, layout);
  std::vector<double> K(pattern.columns.size(), 0.0), M(pattern.columns.size(), 0.0);
  const TetElements elements = computeTetElements(mesh);
  const Eigen::Matrix3d atRest = Eigen::Matrix3d::Zero();  // displacement gradient at rest
  for (int t = 0; t < mesh.tetCount(); ++t) {
    const Tet& tet = mesh.tets[t];
    if (!layout.ownsRowOf(tet)) continue;
    const Material& m = perTet[t];
    const double V = elements.volume[t];
    const Matrix12 Ke = stvkElementTangent(atRest, elements.gradients[t], V, m.lambda(), m.mu());
    // Rows this rank owns only (other ranks add this tet to theirs), free columns only: leaving
    // out the fixed DOFs is the elimination.
    for (int a = 0; a < 4; ++a) {
      if (!layout.owns(layout.dof(tet[a], 0))) continue;
      for (int b = 0; b < 4; ++b) {
        const int64_t first = layout.dof(tet[b], 0);
        if (first < 0) continue;
        const double mass = m.density * V * consistentMassWeight(a, b);
        for (int c = 0; c < 3; ++c) {
          const size_t row = pattern.at(tet[a], c, first, 0);
          for (int d = 0; d < 3; ++d) K[row + d] += Ke(3 * a + c, 3 * b + d);
          M[row + c] += mass;
        }
      }
    }
  }
  return {createMatrix(layout, pattern, K), createMatrix(layout, pattern, M)};
}

} // namespace quiver
