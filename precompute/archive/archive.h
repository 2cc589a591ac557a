#pragma once
// The bake's HDF5 archive, written and read collectively with parallel HDF5 (MPI-IO). Schema:
// formats/ARCHIVE.md. Every call is collective over the communicator the archive was opened on:
// all ranks call it in the same order with the same path, shape and attribute arguments.
// Errors throw std::runtime_error naming the file and the object ("bridge.h5: /modes/vectors: ...").
#include <cstdint>
#include <string>
#include <vector>

#include <mpi.h>

namespace quiver {

class Archive {
public:
  enum class Mode { Create, ReadWrite, ReadOnly };  // Create truncates

  Archive(MPI_Comm comm, const std::string& path, Mode mode);
  ~Archive();
  Archive(const Archive&) = delete;
  Archive& operator=(const Archive&) = delete;

  const std::string& path() const { return path_; }

  // Groups ("/modes"); intermediate groups are created as needed. removeObject unlinks a group or
  // dataset, which must exist; HDF5 does not reclaim its space.
  bool exists(const std::string& objectPath) const;  // group or dataset
  void createGroup(const std::string& groupPath);    // no-op when the group already exists
  void removeObject(const std::string& objectPath);

  // Datasets of any rank (shape; {} is a scalar), row-major, holding data every rank has (only rank
  // 0's `data` is read). A dataset already at the path is replaced (its shape may differ).
  // Stored little-endian as float64, int64 and int32.
  void writeReplicated(const std::string& datasetPath, const std::vector<int64_t>& shape, const double* data);
  void writeReplicated(const std::string& datasetPath, const std::vector<int64_t>& shape, const int64_t* data);
  void writeReplicated(const std::string& datasetPath, const std::vector<int64_t>& shape, const int32_t* data);
  // Reads a whole dataset on every rank; `shape` receives its dimensions. The double reader takes
  // floating-point datasets, the integer reader integer datasets of any width.
  std::vector<double> readReplicatedDouble(const std::string& datasetPath, std::vector<int64_t>& shape) const;
  std::vector<int64_t> readReplicatedInt(const std::string& datasetPath, std::vector<int64_t>& shape) const;

  // Datasets distributed along one axis: the global dataset has `shape`; this rank writes the
  // slab [start, start + count) of axis `axis` (all of the other axes), its `data` row-major in
  // that slab. The ranks' slabs must tile the axis (count may be 0). Written collectively.
  // Example: modes as (k, n, 3) with axis 1 split by vertex ranges. readSlab reads any in-range slab
  // (the ranks' slabs may overlap) and sets `shape` to the whole dataset's dimensions.
  void writeSlab(const std::string& datasetPath, const std::vector<int64_t>& shape, int axis, int64_t start,
                 int64_t count, const double* data);
  std::vector<double> readSlab(const std::string& datasetPath, int axis, int64_t start, int64_t count,
                               std::vector<int64_t>& shape) const;

  // Scalar attributes on a group or dataset ("/" for the file), replaced when already present.
  // Strings are stored as variable-length UTF-8; doubles as float64; integers as int64.
  // hasAttribute is false when the object itself does not exist.
  void setAttribute(const std::string& objectPath, const std::string& name, const std::string& value);
  void setAttribute(const std::string& objectPath, const std::string& name, double value);
  void setAttribute(const std::string& objectPath, const std::string& name, int64_t value);
  bool hasAttribute(const std::string& objectPath, const std::string& name) const;
  std::string stringAttribute(const std::string& objectPath, const std::string& name) const;
  double doubleAttribute(const std::string& objectPath, const std::string& name) const;
  int64_t intAttribute(const std::string& objectPath, const std::string& name) const;

  // Pushes written data to the file (H5Fflush), so a later kill loses nothing written so far.
  void flush();
  // Closes the file now (collective), reporting failure, e.g. before renaming it; the destructor
  // then has nothing left to do. Any later call on the archive throws.
  void close();

private:
  MPI_Comm comm_;
  std::string path_;
  int64_t file_ = -1;  // hid_t
  int rank_ = 0;
};

} // namespace quiver
