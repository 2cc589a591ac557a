#pragma once
// Numbering of the free (unconstrained) degrees of freedom across MPI ranks, in PETSc's
// convention: rank p owns one contiguous range of rows, the DOFs of the vertices the partition
// gave it (increasing vertex order, x y z per vertex). Fixed vertices have no DOFs. Also moves
// row-distributed dense data (eigenvectors, derivatives, bases) between that layout and the
// vertex order used by files.
#include <cstdint>
#include <vector>

#include "common/tet_mesh.h"

#include <Eigen/Core>
#include <mpi.h>

namespace quiver {

class DofLayout {
public:
  // `vertexPart` from the partition; `fixedVertices` ascending. Collective only in spirit: every
  // rank computes the same numbering from the same inputs, without communication.
  DofLayout(MPI_Comm comm, const std::vector<int>& vertexPart, const std::vector<int>& fixedVertices);

  int64_t globalDofs() const { return globalDofs_; }       // 3 x (free vertices)
  int64_t rowStart() const { return rowStart_; }           // this rank's first row
  int64_t localDofs() const { return localDofs_; }         // this rank's rows
  int vertexCount() const { return static_cast<int>(dofOfVertex_.size()); }
  // Global row of vertex v's component c, or -1 when v is fixed.
  int64_t dof(int v, int c) const { return dofOfVertex_[v] < 0 ? -1 : dofOfVertex_[v] + c; }
  const std::vector<int>& ownedVertices() const { return ownedVertices_; }  // in row order
  bool owns(int64_t row) const { return row >= rowStart_ && row < rowStart_ + localDofs_; }
  // Whether this rank owns a row of any of a tet's vertices. Stages that sum element rows add every
  // such tet, in tet order, into their own rows only: each row's sum then runs in the same order
  // on every rank count and every run (no partial sums arriving from other ranks in message order).
  bool ownsRowOf(const Tet& tet) const {
    for (int v : tet)
      if (owns(dof(v, 0))) return true;
    return false;
  }
  MPI_Comm comm() const { return comm_; }

  // Every rank gets the full 3n x cols matrix in vertex order (row 3v + c), zeros at fixed DOFs,
  // from each rank's local rows (localDofs x cols).
  Eigen::MatrixXd gatherToAll(const Eigen::MatrixXd& local) const;

  // This rank's local rows (localDofs x cols) picked out of a full 3n x cols vertex-order matrix.
  Eigen::MatrixXd localRowsOf(const Eigen::MatrixXd& full) const;

  // The vertex range [vertexSlabStart, +vertexSlabCount) this rank writes to files: vertices split
  // evenly by index, independent of the partition, so files do not depend on the rank count.
  int64_t vertexSlabStart() const { return slabStart_; }
  int64_t vertexSlabCount() const { return slabCount_; }

  // This rank's slab of `local` as a (cols, vertexSlabCount, 3) row-major array, zeros at fixed
  // DOFs: the layout of the archive's vector datasets. Collective (all-to-all of rows).
  std::vector<double> toVertexSlab(const Eigen::MatrixXd& local) const;

  // Flips columns of row-distributed data (localDofs x cols) so that each has a positive inner
  // product with one fixed, generic weight vector of the vertex-order DOFs: the sign an
  // eigensolver returns is arbitrary, and this makes files independent of it and of the rank count.
  void orientColumns(Eigen::MatrixXd& local) const;

private:
  MPI_Comm comm_;
  int rank_ = 0, size_ = 1;
  int64_t globalDofs_ = 0, rowStart_ = 0, localDofs_ = 0;
  int64_t slabStart_ = 0, slabCount_ = 0;
  std::vector<int64_t> dofOfVertex_;  // first DOF of each vertex, -1 if fixed
  std::vector<int> ownedVertices_;
  std::vector<int64_t> rowStartOfRank_;  // size_ + 1
};

} // namespace quiver
