#pragma once
// Private to the VTK readers and writers (vtk_legacy.cpp, vtu.cpp): scalar types, turning a VTK
// cell list into tets, region-array names and number formatting.
#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "formats/mesh/byte_cursor.h"
#include "formats/mesh/read_mesh.h"
#include "formats/mesh/write_mesh.h"

namespace quiver::vtk {

constexpr int64_t kTriangle = 5;  // VTK_TRIANGLE
constexpr int64_t kTetra = 10;  // VTK_TETRA

enum class Scalar { Int8, UInt8, Int16, UInt16, Int32, UInt32, Int64, UInt64, Float32, Float64 };

size_t scalarBytes(Scalar s);
bool isFloating(Scalar s);
const char* xmlScalarName(Scalar s);                  // "Float64", "Int32", ...
bool parseXmlScalar(std::string_view name, Scalar& out);  // false for names it does not know

// One value of type `type` read from `in`, as T (int64_t or double). With T = int64_t, floating-point
// types and UInt64 values above INT64_MAX are MeshErrors.
template <class T>
T readScalar(ByteCursor& in, Scalar type, const char* what) {
  static_assert(std::is_same_v<T, int64_t> || std::is_same_v<T, double>);
  const size_t at = in.position();
  switch (type) {
  case Scalar::Int8: return static_cast<T>(in.read<int8_t>(what));
  case Scalar::UInt8: return static_cast<T>(in.read<uint8_t>(what));
  case Scalar::Int16: return static_cast<T>(in.read<int16_t>(what));
  case Scalar::UInt16: return static_cast<T>(in.read<uint16_t>(what));
  case Scalar::Int32: return static_cast<T>(in.read<int32_t>(what));
  case Scalar::UInt32: return static_cast<T>(in.read<uint32_t>(what));
  case Scalar::Int64: return static_cast<T>(in.read<int64_t>(what));
  case Scalar::UInt64: {
    const uint64_t v = in.read<uint64_t>(what);
    if (std::is_same_v<T, int64_t> && v > static_cast<uint64_t>(INT64_MAX))
      in.failAt(at, std::string(what) + " value " + std::to_string(v) + " is too large");
    return static_cast<T>(v);
  }
  case Scalar::Float32:
  case Scalar::Float64:
    if constexpr (std::is_same_v<T, int64_t>) {
      in.failAt(at, std::string(what) + " must have an integer type, not " + xmlScalarName(type));
    } else {
      return type == Scalar::Float32 ? static_cast<T>(in.read<float>(what)) : in.read<double>(what);
    }
  }
  in.failAt(at, "internal: unknown scalar type");
}

// Cell arrays read as the tet's region: "region", "material", "gmsh:physical", "MaterialIds",
// "CellEntityIds" (any case).
bool isRegionArrayName(std::string_view name);

// The warning for a region-named cell array that cannot be used because its type is not integer.
std::string nonIntegerRegionWarning(const std::string& where, std::string_view name);

// A VTK cell list: cell c has type types[c] and the points connectivity[offsets[c] .. offsets[c+1]).
struct CellList {
  std::vector<int64_t> types;
  std::vector<int64_t> offsets;       // types.size() + 1 entries from 0, non-decreasing (checked by readers)
  std::vector<int64_t> connectivity;
  std::vector<int64_t> positions;     // per cell: its line, byte offset or record index in the file
};

// Moves the tets of cell lists into a RawMesh and counts the other cells by type.
class TetCollector {
public:
  explicit TetCollector(RawMesh& out) : out_(out) {}

  // Appends the VTK_TETRA cells of `cells`; point indices are local to a block of `pointCount`
  // points that starts at `pointBase`, cell c gets the file id cellBase + c and the region
  // regions[c] (0 when `regions` is empty). `where(c)` prefixes errors about cell c.
  void add(const CellList& cells, const std::vector<int64_t>& regions, int64_t pointBase, int64_t pointCount,
           int64_t cellBase, const std::function<std::string(size_t)>& where);

  // Sets report.skippedCells and the warning naming the skipped cells by type.
  void finish();

private:
  RawMesh& out_;
  std::map<int64_t, int64_t> skipped_;  // VTK cell type -> count
};

// Checks what the writers need: a region per tet (or none) and a value per vertex in each field.
void checkWritable(const TetMesh& mesh, const std::vector<PointField>& fields, const char* format);

// Shortest text that reads back to the same value (std::to_chars).
void appendNumber(std::string& out, double v);
void appendNumber(std::string& out, int64_t v);

} // namespace quiver::vtk
