#pragma once
// Our readers of two surface formats inside Assimp, in place of Assimp's own. Debian 12's Assimp
// 5.2.5 PLY importer aborts the process (an ai_assert in its triangulation) on valid binary files
// whose data begins with a line-end byte, and walks list counts a file cannot hold for seconds and
// gigabytes (a count of 2e8: 4.5 s and 1.5 GB); its OFF importer takes header counts that
// overflow an unsigned int as whatever they wrap to and allocates that many faces before reading
// on (60 bytes asked for more than 2 GB). Ours bound every count by the bytes left and name the
// line or byte of any problem; the scene they make goes through the same post-processing as every
// other format.
#include <limits>
#include <string>
#include <string_view>
#include <vector>

namespace Assimp {
class Importer;
}

namespace quiver {

// What our readers hand to Assimp: per vertex a position, and normals and texture coordinates
// when the file has them (else empty); faces as runs of vertex indices.
struct PolygonMesh {
  std::vector<float> positions, normals, uvs;
  std::vector<unsigned> faceSizes, indices;
};

// A value read as a float: infinite beyond float's range (where a plain conversion is undefined).
inline float toFloat(double v) {
  constexpr double kMax = std::numeric_limits<float>::max();
  if (v > kMax) return std::numeric_limits<float>::infinity();
  if (v < -kMax) return -std::numeric_limits<float>::infinity();
  return static_cast<float>(v);  // NaN stays NaN
}

// ASCII and binary (both byte orders) PLY: the vertex element's x, y, z (nx, ny, nz; s, t or u, v),
// the face element's vertex_indices (or vertex_index) lists and the tristrips element's strips
// (-1 starts the next); other elements and properties are skipped by their sizes.
PolygonMesh readPly(std::string_view bytes, const std::string& name);

// OFF with the optional prefixes of its header keyword (ST, C, N, 4, n: texture coordinates,
// colours, normals, homogeneous and dimension), comments from '#'; colours are skipped.
PolygonMesh readOff(std::string_view bytes, const std::string& name);

// Replaces `importer`'s PLY and OFF importers with ours; `name` is the file named in their errors.
void useOwnReaders(Assimp::Importer& importer, const std::string& name);

} // namespace quiver
