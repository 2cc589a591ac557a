#pragma once
// NumPy .npy files (format versions 1.0-3.0) holding 1-D or 2-D float64 arrays, for exporting the
// bake's results to numpy and for importing a user basis. Little-endian '<f8' is written; '<f8',
// '>f8', '<f4' and '>f4' are read (converted to double), in C or Fortran order.
// Errors throw std::runtime_error naming the file and the byte offset or header field.
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace quiver {

struct NpyArray {
  std::vector<int64_t> shape;  // 1 or 2 dimensions
  std::vector<double> data;    // row-major (C order) whatever the file's order
};

// Bytes of a .npy file holding `data` (row-major) with `shape` as '<f8', C order.
std::string formatNpy(const std::vector<int64_t>& shape, const double* data);

// Parses a .npy held in memory; `file` names it in messages. Sizes are checked against the
// bytes present before anything is allocated.
NpyArray parseNpy(std::string_view bytes, const std::string& file);

// Atomic write (temporary + rename) / whole-file read.
void writeNpy(const std::string& path, const std::vector<int64_t>& shape, const double* data);
NpyArray readNpy(const std::string& path);

} // namespace quiver
