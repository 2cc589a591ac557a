#pragma once
// Stage "surface", before "mesh": an artist's triangle surface (OBJ, glTF/GLB, STL, PLY, FBX and
// the rest Assimp reads) is read, checked and repaired as it can be (common/surface_check.h),
// tetrahedralized by Gmsh (precompute/tet_mesher.h) and written as NAME.tets.vtu, which the mesh
// stage reads like any tet mesh. Then the render mesh (--render-mesh FILE, by default the input
// surface) is bound to the tets (common/embedding.h) for NAME.qvr's RENDER_MESH.
#include <string>
#include <vector>

#include "common/embedding.h"
#include "common/surface_check.h"
#include "formats/mesh/read_surface.h"
#include "precompute/bake_context.h"
#include "precompute/tet_mesher.h"

namespace quiver {

struct SurfaceSettings {
  MesherSettings mesher;
  SurfaceCheckOptions checks{true};  // holes closed (and said) by default: artists' meshes often have some
  std::string renderMesh;     // --render-mesh; "" : the input when it is a surface, else none
  double embedTolerance = 0;  // m: how far outside the tets a render vertex may lie; 0: two mean tet edges or 10% of its size
};

// Collective: rank 0 checks and meshes `input` and writes NAME.tets.vtu (every rank throws rank 0's
// error); returns that path. Rank 0 reports the repairs, the counts, the quality and the volumes.
std::string meshSurface(const BakeContext& ctx, const std::string& input, const SurfaceSettings& settings,
                        const std::string& outputName);

struct RenderInputs {
  std::string path;  // "" : no render mesh
  SurfaceMesh::Render render;
  Embedding embedding;
};

// Every rank alike: reads the render mesh (the input when it is a surface, unless --render-mesh
// names another) and binds it to `mesh`; throws naming the file and the first vertex too far out.
RenderInputs bindRenderMesh(const BakeContext& ctx, const std::string& input, const SurfaceSettings& settings, const TetMesh& mesh);

} // namespace quiver
