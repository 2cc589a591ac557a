#include "precompute/checkpoint.h"

#include <stdexcept>

namespace quiver {

namespace {
const char* kHash = "input_hash";
} // namespace

void writeVector(Archive& archive, const std::string& dataset, const std::vector<double>& values) {
  archive.writeReplicated(dataset, {static_cast<int64_t>(values.size())}, values.data());
}

std::vector<double> readVector(const Archive& archive, const std::string& dataset) {
  std::vector<int64_t> shape;
  return archive.readReplicatedDouble(dataset, shape);
}

void resetGroup(Archive& archive, const std::string& group) {
  if (archive.exists(group)) archive.removeObject(group);
  archive.createGroup(group);
}

void finishGroup(Archive& archive, const std::string& group, const std::string& inputHash) {
  archive.setAttribute(group, kHash, inputHash);
  archive.flush();
}

std::string storedInputHash(const Archive& archive, const std::string& group) {
  if (!archive.exists(group) || !archive.hasAttribute(group, kHash)) return "";
  return archive.stringAttribute(group, kHash);
}

void writeVectors(Archive& archive, const std::string& dataset, const Eigen::MatrixXd& local, const DofLayout& layout) {
  const std::vector<double> slab = layout.toVertexSlab(local);
  archive.writeSlab(dataset, {local.cols(), layout.vertexCount(), 3}, 1, layout.vertexSlabStart(),
                    layout.vertexSlabCount(), slab.data());
}

Eigen::MatrixXd readVectors(const Archive& archive, const std::string& dataset, const DofLayout& layout) {
  std::vector<int64_t> shape;
  const std::vector<double> all = archive.readReplicatedDouble(dataset, shape);
  if (shape.size() != 3 || shape[1] != layout.vertexCount() || shape[2] != 3)
    throw std::runtime_error(archive.path() + ": " + dataset + ": expected shape (columns, " +
                             std::to_string(layout.vertexCount()) + ", 3)");
  const int64_t cols = shape[0], n = shape[1];
  Eigen::MatrixXd full(3 * n, cols);
  for (int64_t j = 0; j < cols; ++j)
    for (int64_t r = 0; r < 3 * n; ++r) full(r, j) = all[j * 3 * n + r];
  return layout.localRowsOf(full);
}

} // namespace quiver
