#include "precompute/dof_layout.h"

#include <cmath>
#include <stdexcept>

namespace quiver {

DofLayout::DofLayout(MPI_Comm comm, const std::vector<int>& vertexPart, const std::vector<int>& fixedVertices)
    : comm_(comm) {
  MPI_Comm_rank(comm, &rank_);
  MPI_Comm_size(comm, &size_);
  const int n = static_cast<int>(vertexPart.size());
  std::vector<char> fixed(n, 0);
  for (int v : fixedVertices) fixed[v] = 1;
  dofOfVertex_.assign(n, -1);
  rowStartOfRank_.assign(size_ + 1, 0);
  int64_t next = 0;
  for (int p = 0; p < size_; ++p) {
    rowStartOfRank_[p] = next;
    for (int v = 0; v < n; ++v)
      if (vertexPart[v] == p && !fixed[v]) {
        dofOfVertex_[v] = next;
        next += 3;
        if (p == rank_) ownedVertices_.push_back(v);
      }
  }
  rowStartOfRank_[size_] = next;
  globalDofs_ = next;
  rowStart_ = rowStartOfRank_[rank_];
  localDofs_ = rowStartOfRank_[rank_ + 1] - rowStart_;
  slabStart_ = static_cast<int64_t>(n) * rank_ / size_;
  slabCount_ = static_cast<int64_t>(n) * (rank_ + 1) / size_ - slabStart_;
}

Eigen::MatrixXd DofLayout::gatherToAll(const Eigen::MatrixXd& local) const {
  const int cols = static_cast<int>(local.cols());
  // Row-major packing so that the ranks' blocks concatenate in global row order.
  const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> mine = local;
  std::vector<int> counts(size_), displs(size_);
  for (int p = 0; p < size_; ++p) {
    const int64_t c = (rowStartOfRank_[p + 1] - rowStartOfRank_[p]) * cols, d = rowStartOfRank_[p] * cols;
    if (c > INT32_MAX || d > INT32_MAX) throw std::runtime_error("gatherToAll: data too large for one MPI message");
    counts[p] = static_cast<int>(c);
    displs[p] = static_cast<int>(d);
  }
  std::vector<double> all(static_cast<size_t>(globalDofs_) * cols);
  MPI_Allgatherv(mine.data(), counts[rank_], MPI_DOUBLE, all.data(), counts.data(), displs.data(), MPI_DOUBLE, comm_);
  Eigen::MatrixXd full = Eigen::MatrixXd::Zero(3 * static_cast<int64_t>(vertexCount()), cols);
  for (int v = 0; v < vertexCount(); ++v)
    if (dofOfVertex_[v] >= 0)
      for (int c = 0; c < 3; ++c)
        for (int j = 0; j < cols; ++j) full(3 * v + c, j) = all[(dofOfVertex_[v] + c) * cols + j];
  return full;
}

void DofLayout::orientColumns(Eigen::MatrixXd& local) const {
  Eigen::VectorXd mine = Eigen::VectorXd::Zero(local.cols()), total(local.cols());
  for (size_t i = 0; i < ownedVertices_.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      const double d = 3.0 * ownedVertices_[i] + c;
      mine += (1.0 + 0.5 * std::sin(0.7 * d + 0.3)) * local.row(3 * i + c).transpose();
    }
  MPI_Allreduce(mine.data(), total.data(), static_cast<int>(local.cols()), MPI_DOUBLE, MPI_SUM, comm_);
  for (int j = 0; j < local.cols(); ++j)
    if (total[j] < 0) local.col(j) *= -1;
}

Eigen::MatrixXd DofLayout::localRowsOf(const Eigen::MatrixXd& full) const {
  Eigen::MatrixXd local(localDofs_, full.cols());
  for (size_t i = 0; i < ownedVertices_.size(); ++i) local.middleRows(3 * i, 3) = full.middleRows(3 * ownedVertices_[i], 3);
  return local;
}

std::vector<double> DofLayout::toVertexSlab(const Eigen::MatrixXd& local) const {
  const int cols = static_cast<int>(local.cols());
  const int n = vertexCount();
  auto slabOf = [&](int v) {
    // The rank p with n*p/size <= v < n*(p+1)/size.
    int p = static_cast<int>((static_cast<int64_t>(v) * size_ + size_ - 1) / n);
    while (p > 0 && static_cast<int64_t>(n) * p / size_ > v) --p;
    while (static_cast<int64_t>(n) * (p + 1) / size_ <= v) ++p;
    return p;
  };
  auto ownerOf = [&](int v) {
    if (dofOfVertex_[v] < 0) return -1;
    int p = 0;
    while (rowStartOfRank_[p + 1] <= dofOfVertex_[v]) ++p;
    return p;
  };
  // Send each owned vertex's 3 x cols values to the rank whose slab holds it, in vertex order.
  std::vector<std::vector<double>> outgoing(size_);
  for (size_t i = 0; i < ownedVertices_.size(); ++i) {
    auto& buffer = outgoing[slabOf(ownedVertices_[i])];
    for (int j = 0; j < cols; ++j)
      for (int c = 0; c < 3; ++c) buffer.push_back(local(3 * i + c, j));
  }
  std::vector<int> sendCounts(size_), sendDispls(size_), recvCounts(size_, 0), recvDispls(size_);
  std::vector<double> send;
  for (int p = 0; p < size_; ++p) {
    sendDispls[p] = static_cast<int>(send.size());
    sendCounts[p] = static_cast<int>(outgoing[p].size());
    send.insert(send.end(), outgoing[p].begin(), outgoing[p].end());
  }
  std::vector<int> owner(slabCount_);
  for (int64_t i = 0; i < slabCount_; ++i) {
    owner[i] = ownerOf(static_cast<int>(slabStart_ + i));
    if (owner[i] >= 0) recvCounts[owner[i]] += 3 * cols;
  }
  int total = 0;
  for (int p = 0; p < size_; ++p) {
    recvDispls[p] = total;
    total += recvCounts[p];
  }
  std::vector<double> received(total);
  MPI_Alltoallv(send.data(), sendCounts.data(), sendDispls.data(), MPI_DOUBLE, received.data(), recvCounts.data(),
                recvDispls.data(), MPI_DOUBLE, comm_);
  std::vector<double> slab(static_cast<size_t>(cols) * slabCount_ * 3, 0.0);
  std::vector<int> cursor = recvDispls;
  for (int64_t i = 0; i < slabCount_; ++i) {
    if (owner[i] < 0) continue;
    const double* values = &received[cursor[owner[i]]];
    cursor[owner[i]] += 3 * cols;
    for (int j = 0; j < cols; ++j)
      for (int c = 0; c < 3; ++c) slab[(static_cast<size_t>(j) * slabCount_ + i) * 3 + c] = values[3 * j + c];
  }
  return slab;
}

} // namespace quiver
