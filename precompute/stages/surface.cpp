#include "precompute/stages/surface.h"

#include <algorithm>
#include <cstdio>

#include <Eigen/Geometry>
#include <iostream>

#include "common/mesh_error.h"
#include "common/mesh_quality.h"
#include "common/surface_check.h"
#include "formats/mesh/write_mesh.h"
#include "formats/model/qvr.h"

namespace quiver {

std::string meshSurface(const BakeContext& ctx, const std::string& input, const SurfaceSettings& s, const std::string& outputName) {
  const std::string path = outputName + ".tets.vtu";
  ctx.onRankZero([&] {
    const SurfaceMesh surface = readSurfaceFile(input);
    const CheckedSurface checked = checkSurface(surface.positions, surface.triangles, input, s.checks);
    for (const std::string& repair : checked.repairs) std::cerr << "quiver-bake: warning: " << input << ": " << repair << "\n";
    const MesherResult tets = tetrahedralize(checked, s.mesher, input);
    writeMeshFile(path, tets.mesh);
    char text[320];
    std::snprintf(text, sizeof text,
                  "%s: %zu triangles -> %d tets (edge %.3g m) by gmsh in %.1f s, smallest dihedral angle %.1f degrees "
                  "(floor %.1f); volume %.6g m^3 (surface %.6g m^3)",
                  input.c_str(), checked.triangles.size(), tets.mesh.tetCount(), tets.edgeLength, tets.seconds, tets.minDihedral,
                  s.mesher.minDihedral, totalVolume(tets.mesh), checked.volume);
    ctx.progress(text);
    ctx.progress("wrote " + path);
  });
  return path;
}

RenderInputs bindRenderMesh(const BakeContext& ctx, const std::string& input, const SurfaceSettings& s, const TetMesh& mesh) {
  RenderInputs out;
  out.path = !s.renderMesh.empty() ? s.renderMesh : isTetMeshPath(input) ? "" : input;
  if (out.path.empty()) return out;
  // Every rank reads and binds alike; a rank that fails alone (a file missing on its node) makes all fail.
  std::string error;
  try {
    out.render = readSurfaceFile(out.path).render;
    const size_t vertices = out.render.positions.size() / 3, triangles = out.render.triangles.size() / 3;
    if (out.render.triangles.empty())
      throw MeshError(out.path + ": --render-mesh needs a triangle mesh file (OBJ, glTF, STL, PLY, FBX, ...), not a tet mesh");
    if (vertices < 3 || vertices > qvr::kMaxRenderCount || triangles > qvr::kMaxRenderCount)
      throw MeshError(out.path + ": " + std::to_string(vertices) + " vertices and " + std::to_string(triangles) +
                      " triangles: a render mesh holds 3 to 2^26 vertices and at most 2^26 triangles");
    std::vector<double> points(out.render.positions.begin(), out.render.positions.end());
    double tolerance = s.embedTolerance;
    if (!(tolerance > 0)) {  // thin features coarse tets do not reach: two tet edges, or 10% of the mesh's size
      Eigen::AlignedBox3d box;
      for (size_t i = 0; i + 2 < points.size(); i += 3) box.extend(Eigen::Vector3d(points[i], points[i + 1], points[i + 2]));
      tolerance = std::max(2 * measureQuality(mesh).edgeLength.mean, 0.1 * box.diagonal().norm());
    }
    out.embedding = embedPoints(mesh, points, tolerance, out.path);
    char text[240];
    std::snprintf(text, sizeof text, "render mesh %s: %zu vertices, %zu triangles; %d outside the tets, at most %.3g m (tolerance %.3g m)",
                  out.path.c_str(), vertices, triangles, out.embedding.outside, out.embedding.farthest, tolerance);
    ctx.progress(text);
  } catch (const std::exception& e) {
    error = e.what();
  }
  error = ctx.agreeOnError(error);
  if (!error.empty()) throw MeshError(error);
  return out;
}

} // namespace quiver
