#pragma once
// Reading triangle surfaces: artists' formats through Assimp (OBJ, STL, PLY, glTF/GLB, FBX, OFF and
// the rest it knows), or the boundary of a tet mesh in any format readMeshFile() reads.
#include <string>
#include <vector>

namespace quiver {

struct SurfaceMesh {
  std::vector<double> positions;  // 3 per vertex
  std::vector<int> triangles;     // 3 vertex indices each
};

// All meshes of the file's scene in one, their node transforms applied, polygons triangulated and
// vertices at the same position welded (formats split them by normal or UV). Points and lines are
// left out. Throws MeshError "PATH: ..." when the file cannot be read or holds no triangle.
SurfaceMesh readSurfaceFile(const std::string& path);

} // namespace quiver
