#include "precompute/tet_mesher.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <unistd.h>

#include "common/mesh_error.h"
#include "common/mesh_quality.h"
#include "formats/mesh/read_mesh.h"
#include "precompute/child_process.h"

namespace quiver {

namespace fs = std::filesystem;

namespace {

// Tets per unit of volume / h^3 that Gmsh's Delaunay mesher makes at size h: about 5 on fine meshes
// of spheres and tori, 7 to 8 when h is a third of the body (its surface layer): the first guess of h
// for a target count, corrected once after a run.
constexpr double kTetsPerH3 = 6;

// A private folder for the run's files, removed with it.
struct TempFolder {
  fs::path path;
  TempFolder(const TempFolder&) = delete;
  TempFolder& operator=(const TempFolder&) = delete;
  TempFolder() {
    std::string pattern = (fs::temp_directory_path() / "quiver-mesher-XXXXXX").string();
    if (!mkdtemp(pattern.data())) throw std::runtime_error("cannot make a temporary folder in " + fs::temp_directory_path().string());
    path = pattern;
  }
  ~TempFolder() {
    std::error_code ignored;
    fs::remove_all(path, ignored);
  }
};

// Float32 coordinates relative to `origin` (the surface's centre: a model far from the origin keeps its precision).
void writeBinaryStl(const fs::path& path, const CheckedSurface& s, const Eigen::Vector3d& origin) {
  std::ofstream out(path, std::ios::binary);
  char header[80] = "quiver surface";
  out.write(header, sizeof header);
  const uint32_t count = static_cast<uint32_t>(s.triangles.size());
  out.write(reinterpret_cast<const char*>(&count), 4);
  for (const auto& t : s.triangles) {
    float record[12] = {};
    for (int k = 0; k < 3; ++k)
      for (int a = 0; a < 3; ++a) record[3 + 3 * k + a] = static_cast<float>(s.positions[3 * t[k] + a] - origin[a]);
    out.write(reinterpret_cast<const char*>(record), sizeof record);
    const uint16_t attribute = 0;
    out.write(reinterpret_cast<const char*>(&attribute), 2);
  }
  if (!out) throw std::runtime_error("cannot write " + path.string());
}

// The quality pass: Gmsh optimises tets below `threshold` (0.7 lifted the worst dihedral of a sphere
// from 8 to 16 degrees; 0.9 helps more but made surface slivers on a torus, so it is the retry).
std::string script(double h, double threshold) {
  std::ostringstream g;
  g.precision(17);
  g << "Merge \"surface.stl\";\n"
       "ClassifySurfaces{40 * Pi / 180, 1, 1, Pi};\n"  // patches split at 40 degree creases, reparametrised
       "CreateGeometry;\n"
       "Surface Loop(1) = Surface{:};\n"
       "Volume(1) = {1};\n"
       "Physical Volume(1) = {1};\n"
    << "Mesh.MeshSizeMin = " << h << ";\nMesh.MeshSizeMax = " << h << ";\n"
    << "Mesh.MeshSizeFromPoints = 0;\nMesh.MeshSizeFromCurvature = 0;\nMesh.MeshSizeExtendFromBoundary = 1;\n"
       "Mesh.Algorithm = 6;\nMesh.Algorithm3D = 1;\n"  // Frontal-Delaunay surfaces, Delaunay volume
       "Mesh.Optimize = 1;\n"  // Debian's gmsh has no Netgen optimiser
    << "Mesh.OptimizeThreshold = " << threshold << ";\n"
    << "Mesh.Smoothing = 5;\n"
       "Mesh.MshFileVersion = 2.2;\n";
  return g.str();
}

std::string lastLines(const fs::path& log, int count) {
  std::ifstream in(log);
  std::vector<std::string> lines;
  // Its errors, less the summary it closes with.
  for (std::string line; std::getline(in, line);)
    if (line.rfind("Error", 0) == 0 && line.find("---") == std::string::npos && line.find("error summary") == std::string::npos &&
        line.find(" warnings") == std::string::npos && line.find(" error") == std::string::npos &&
        line.find("full log") == std::string::npos)
      lines.push_back(line);
  std::string out;
  for (size_t k = lines.size() > size_t(count) ? lines.size() - count : 0; k < lines.size(); ++k) out += "\n  " + lines[k];
  return out.empty() ? " (no message; see gmsh's output above)" : out;
}

} // namespace

MesherResult tetrahedralize(const CheckedSurface& surface, const MesherSettings& s, const std::string& name) {
  const auto fail = [&](const std::string& what) { throw MeshError(name + ": " + what); };
  if (std::system(("command -v '" + s.program + "' > /dev/null 2>&1").c_str()) != 0)
    fail("needs the mesher '" + s.program + "' (Debian package gmsh, which scripts/quiver installs) to make tets of a surface");
  if (!(s.edgeLength > 0) && s.targetTets < 1) fail("--tets must be at least 1");
  if (!(s.timeLimit > 0)) fail("--mesher-time-limit must be > 0 s");
  TempFolder folder;
  Eigen::Vector3d low = Eigen::Vector3d::Constant(INFINITY), high = -low;
  for (const auto& t : surface.triangles)
    for (int v : t)
      for (int a = 0; a < 3; ++a) low[a] = std::min(low[a], surface.positions[3 * v + a]), high[a] = std::max(high[a], surface.positions[3 * v + a]);
  const Eigen::Vector3d origin = 0.5 * (low + high);
  writeBinaryStl(folder.path / "surface.stl", surface, origin);
  MesherResult result;
  double h = s.edgeLength > 0 ? s.edgeLength : std::cbrt(kTetsPerH3 * surface.volume / s.targetTets);
  const auto start = std::chrono::steady_clock::now();
  // Passes until the floor is met: the quality pass, a stronger one, then the first with h 2% larger
  // (the worst tets sit on the surface, where a slightly different surface mesh moves them).
  const struct {
    double threshold, scale;
  } passes[] = {{0.7, 1.0}, {0.9, 1.0}, {0.7, 1.02}};
  for (const auto& pass : passes) {
    // A target count gets one correction of h from the first run's count.
    const int attempts = s.edgeLength > 0 || result.runs ? 1 : 2;
    for (int attempt = 0; attempt < attempts; ++attempt) {
      std::ofstream(folder.path / "surface.geo") << script(h * pass.scale, pass.threshold);
      const std::string command = "cd '" + folder.path.string() + "' && exec '" + s.program +
                                  "' surface.geo -3 -nt 1 -format msh22 -o tets.msh > gmsh.log 2>&1";
      ++result.runs;
      int status = 0;
      try {
        status = runChild(command, s.timeLimit);
      } catch (const OutOfTime&) {
        char text[200];
        std::snprintf(text, sizeof text, "gmsh ran past the time limit of %g s (--mesher-time-limit) at edge %.3g m; "
                      "a larger --edge or fewer --tets, or a longer limit, helps", s.timeLimit, h * pass.scale);
        fail(text);
      }
      // A failed run may still write an empty .msh.
      if (status != 0 || !fs::exists(folder.path / "tets.msh") || fs::file_size(folder.path / "tets.msh") < 200)
        fail("gmsh could not make tets of the surface:" + lastLines(folder.path / "gmsh.log", 3));
      CheckedMesh checked = loadMesh((folder.path / "tets.msh").string());
      result.mesh = std::move(checked.mesh);
      for (Eigen::Vector3d& x : result.mesh.vertices) x += origin;
      result.mesh.tetRegion.assign(result.mesh.tets.size(), 0);
      result.edgeLength = h * pass.scale;
      fs::remove(folder.path / "tets.msh");
      const double ratio = double(result.mesh.tetCount()) / s.targetTets;
      if (s.edgeLength > 0 || (ratio > 0.85 && ratio < 1.15)) break;
      h *= std::cbrt(ratio);
    }
    result.minDihedral = measureQuality(result.mesh).dihedralDegrees.min;
    if (result.minDihedral >= s.minDihedral) break;
  }
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (result.minDihedral < s.minDihedral) {
    char text[160];
    std::snprintf(text, sizeof text, "the tets' smallest dihedral angle is %.2f degrees, below the floor of %.2f (--min-dihedral)",
                  result.minDihedral, s.minDihedral);
    fail(std::string(text) + "; a larger --edge or --tets, or a smoother surface, helps");
  }
  return result;
}

} // namespace quiver
