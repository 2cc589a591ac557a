// quiver-bake: turns a tetrahedral mesh into a reduced model. Runs on one or many MPI ranks
// (mpirun -n N quiver-bake ...); PETSc/SLEPc options (-eps_*, -ksp_*, -log_view) pass through.
#include <iostream>

#include "apps/support/mesh_options.h"
#include "precompute/bake_context.h"
#include "precompute/stages/partition.h"

using namespace quiver;

int main(int argc, char** argv) {
  std::vector<std::string> own, petsc;
  splitPetscOptions(argc, argv, own, petsc);

  CLI::App app{"quiver-bake: reduced St.Venant-Kirchhoff model from a tetrahedral mesh.\n"
               "PETSc/SLEPc options (-eps_type, -ksp_type, -log_view, -options_file, ...) pass through."};
  app::MeshOptions meshOptions;
  app::FixedVertexOptions fixedOptions;
  MaterialOverride material;
  std::string output;
  bool quiet = false;
  meshOptions.addTo(app);
  fixedOptions.addTo(app);
  app.add_option("--E", material.youngsModulus, "Young's modulus in Pa (> 0); overrides the mesh file's materials");
  app.add_option("--nu", material.poissonRatio, "Poisson ratio in (-1, 0.5); overrides the mesh file's materials");
  app.add_option("--density", material.density, "Density in kg/m^3 (> 0); overrides the mesh file's materials");
  app.add_option("-o,--output", output, "Output name: writes NAME.h5 (and NAME.qvr)")->required();
  app.add_flag("--quiet", quiet, "Print nothing but errors");

  std::vector<char*> ownArgv;
  for (auto& a : own) ownArgv.push_back(a.data());
  try {
    app.parse(static_cast<int>(ownArgv.size()), ownArgv.data());
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }

  BakeContext ctx(petsc);
  ctx.quiet = quiet;
  std::string error;
  try {
    // Explicit values are checked before any work starts.
    Material check;
    if (material.youngsModulus) check.youngsModulus = *material.youngsModulus;
    if (material.poissonRatio) check.poissonRatio = *material.poissonRatio;
    if (material.density) check.density = *material.density;
    if (std::string bad = checkMaterial(check); !bad.empty()) throw std::invalid_argument(bad);

    CheckedMesh mesh = meshOptions.load(ctx.rank() == 0 ? "quiver-bake" : "");
    std::vector<int> fixed = fixedOptions.select(mesh);
    auto materials = resolveTetMaterials(mesh.mesh, Material{}, material);
    for (const Material& m : materials)
      if (std::string bad = checkMaterial(m); !bad.empty()) throw std::invalid_argument(bad);
    ctx.progress("mesh " + meshOptions.path + ": " + std::to_string(mesh.mesh.vertexCount()) + " vertices, " +
                 std::to_string(mesh.mesh.tetCount()) + " tets, " + std::to_string(fixed.size()) + " fixed vertices" +
                 (fixed.empty() ? " (free object: rigid modes will be skipped)" : ""));

    Partition part = partitionMesh(mesh.mesh, {ctx.size()});
    std::vector<int> tetsPerPart(ctx.size(), 0);
    for (int p : part.tetPart) ++tetsPerPart[p];
    std::string sizes;
    for (int n : tetsPerPart) sizes += (sizes.empty() ? "" : " ") + std::to_string(n);
    ctx.progress("partition: " + std::to_string(ctx.size()) + " part(s), tets per part [" + sizes + "], " +
                 std::to_string(part.cutFaces) + " cut faces");
    ctx.progress("the mode, basis and polynomial stages are not built yet: stopping after the partition");
  } catch (const std::exception& e) {
    error = e.what();
  }
  error = ctx.agreeOnError(error);
  if (!error.empty()) {
    if (ctx.rank() == 0) std::cerr << "quiver-bake: error: " << error << std::endl;
    return 1;
  }
  return 0;
}
