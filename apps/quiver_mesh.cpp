// quiver-mesh: inspect, convert and generate tetrahedral meshes.
#include <iostream>
#include <map>
#include <sstream>

#include <nlohmann/json.hpp>

#include "apps/support/mesh_options.h"
#include "common/box_mesh.h"
#include "common/mesh_quality.h"
#include "formats/mesh/write_mesh.h"

using namespace quiver;
using nlohmann::ordered_json;

namespace {

// About a gigabyte of mesh in memory.
constexpr double kMaxBeamTets = 5e7;

ordered_json rangeJson(const Range& r) { return {{"min", r.min}, {"mean", r.mean}, {"max", r.max}}; }

ordered_json describe(const std::string& path, const CheckedMesh& m, const std::vector<int>* fixed) {
  const TetMesh& mesh = m.mesh;
  const auto box = boundingBox(mesh);
  const MeshQuality q = measureQuality(mesh);
  ordered_json j;
  j["file"] = path;
  j["format"] = meshFormatName(detectMeshFormat(path, readFileBytes(path).substr(0, 256)));
  j["vertices"] = mesh.vertexCount();
  j["tets"] = mesh.tetCount();
  j["volume"] = totalVolume(mesh);
  j["bbox"] = {{"min", {box[0].x(), box[0].y(), box[0].z()}}, {"max", {box[1].x(), box[1].y(), box[1].z()}}};
  j["quality"] = {{"normalised_volume", rangeJson(q.normalisedVolume)},
                  {"dihedral_degrees", rangeJson(q.dihedralDegrees)},
                  {"edge_length", rangeJson(q.edgeLength)},
                  {"tet_volume", rangeJson(q.tetVolume)}};
  std::map<int, int> regions;
  for (int r : mesh.tetRegion) ++regions[r];
  ordered_json regionJson = ordered_json::object();
  for (const auto& [r, n] : regions) regionJson[std::to_string(r)] = n;
  j["regions"] = regionJson;
  ordered_json materials = ordered_json::array();
  for (size_t k = 0; k < mesh.materials.size(); ++k) {
    const Material& mat = mesh.materials[k];
    int count = static_cast<int>(std::count(mesh.tetMaterial.begin(), mesh.tetMaterial.end(), static_cast<int>(k)));
    materials.push_back({{"name", mat.name}, {"E", mat.youngsModulus}, {"nu", mat.poissonRatio},
                         {"density", mat.density}, {"tets", count}});
  }
  j["materials"] = materials;
  j["skipped_cells"] = m.skippedCells;
  j["dropped_vertices"] = static_cast<int64_t>(m.loadedVertex.size() - m.fileVertex.size());
  j["flipped_tets"] = m.flippedTets;
  if (fixed) j["fixed_vertices"] = fixed->size();
  j["warnings"] = m.warnings;
  return j;
}

} // namespace

int main(int argc, char** argv) {
  const std::string tool = "quiver-mesh";
  CLI::App app{"quiver-mesh: inspect, convert and generate tetrahedral meshes"};
  app.require_subcommand(1);

  CLI::App* info = app.add_subcommand("info", "Validate a mesh and print one JSON object describing it");
  app::MeshOptions infoMesh;
  app::FixedVertexOptions infoFixed;
  infoMesh.addTo(*info);
  infoFixed.addTo(*info);

  CLI::App* convert = app.add_subcommand("convert", "Validate a mesh and write it in another format (by extension)");
  app::MeshOptions convertMesh;
  std::string convertOut;
  convertMesh.addTo(*convert);
  convert->add_option("output", convertOut, "Output file: .vtu .vtk .msh (Gmsh 4.1) .mesh (Medit) .veg .node/.ele")
      ->required();

  CLI::App* beam = app.add_subcommand("beam", "Generate a box mesh [0,Lx]x[0,Ly]x[0,Lz], six tets per cell");
  std::vector<double> size{1, 0.1, 0.1};
  std::vector<int> cells{20, 2, 2};
  std::string beamOut;
  beam->add_option("--size", size, "Box edge lengths Lx,Ly,Lz in mesh units (> 0)")
      ->delimiter(',')
      ->expected(3)
      ->capture_default_str()
      ->check(quiver::app::Positive);
  beam->add_option("--cells", cells, "Cells along x,y,z (>= 1)")
      ->delimiter(',')
      ->expected(3)
      ->capture_default_str()
      ->check(CLI::Range(1, 1000));
  beam->add_option("-o,--output", beamOut, "Output mesh file (format by extension)")->required();

  return app::runTool(tool, app, argc, argv, [&]() {
    if (*info) {
      CheckedMesh m = infoMesh.load(tool);
      std::vector<int> fixed;
      if (infoFixed.given()) fixed = infoFixed.select(m);
      std::cout << describe(infoMesh.path, m, infoFixed.given() ? &fixed : nullptr).dump(2) << "\n";
    } else if (*convert) {
      const CheckedMesh m = convertMesh.load(tool);
      for (const std::string& dropped : droppedByFormat(convertOut, m.mesh)) std::cerr << tool << ": warning: " << dropped << "\n";
      writeMeshFile(convertOut, m.mesh);
    } else if (*beam) {
      for (double length : size)
        if (length > 1e9) throw std::runtime_error("--size: an edge beyond 1e9 (in metres?)");
      const double tets = 6.0 * cells[0] * cells[1] * cells[2];
      if (tets > kMaxBeamTets)
        throw std::runtime_error("--cells: " + std::to_string(static_cast<long long>(tets)) + " tets; at most " +
                                 std::to_string(static_cast<long long>(kMaxBeamTets)));
      const TetMesh mesh = makeBoxMesh({size[0], size[1], size[2]}, {cells[0], cells[1], cells[2]});
      // Cells far flatter one way than another make tets the bake refuses as degenerate.
      const double quality = measureQuality(mesh).normalisedVolume.min, least = MeshCheckOptions{}.degenerateTolerance;
      if (!(quality >= least)) {
        std::ostringstream message;
        message << "--size and --cells make cells so flat that their tets are degenerate (normalised volume " << quality
                << ", below " << least << "): give the cells edges of more alike lengths";
        throw std::runtime_error(message.str());
      }
      writeMeshFile(beamOut, mesh);
    }
    return 0;
  });
}
