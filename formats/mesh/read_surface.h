#pragma once
// Reading triangle surfaces: artists' formats through Assimp (OBJ, STL, PLY, glTF/GLB, FBX, OFF and
// the rest it knows), or the boundary of a tet mesh in any format readMeshFile() reads.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace quiver {

struct SurfaceMesh {
  std::vector<double> positions;  // 3 per vertex
  std::vector<int> triangles;     // 3 vertex indices each
  // The same triangles as the file gives them, for drawing: vertices split by normal and UV (not
  // welded), normals and the first UV set (empty when no mesh of the file has them; a mesh without
  // them where others have them gets generated normals and UV 0). Empty for a tet mesh's boundary.
  struct Render {
    std::vector<float> positions, normals, uvs;  // 3, 3 and 2 per vertex
    std::vector<uint32_t> triangles;
  } render;
};

// All meshes of the file's scene in one, their node transforms applied, polygons triangulated and
// vertices at the same position welded (formats split them by normal or UV). Points and lines are
// left out. Throws MeshError "PATH: ..." when the file cannot be read or holds no triangle.
SurfaceMesh readSurfaceFile(const std::string& path);
// The same from bytes in memory, in the format of `extension` ("obj", "stl", "ply", "glb", ...);
// messages name `name`. (Formats that refer to other files cannot find them.)
SurfaceMesh readSurfaceMemory(const void* data, size_t size, const std::string& extension, const std::string& name);

// Whether `path` names a tet mesh by its extension (.vtu .vtk .msh .mesh .veg .node .ele); any
// other file is a surface for Assimp.
bool isTetMeshPath(const std::string& path);

} // namespace quiver
