// quiver-bake: turns a tetrahedral mesh into a reduced model. Runs on one or many MPI ranks
// (mpirun -n N quiver-bake ...); PETSc/SLEPc options (-factor_*, -eps_*, -st_*, -log_view)
// pass through to the solvers.
#include <csignal>
#include <cstdlib>
#include <iostream>

#include "apps/support/mesh_options.h"
#include "formats/mesh/read_surface.h"
#include "precompute/bake.h"
#include "precompute/blas_core.h"
#include "precompute/child_process.h"

using namespace quiver;

int main(int argc, char** argv) {
  const std::string blas = chooseBlasCore(argv);  // may run the program again: before anything else
  std::vector<std::string> own, petsc;
  splitPetscOptions(argc, argv, own, petsc);

  CLI::App app{"quiver-bake: reduced St.Venant-Kirchhoff model of a tetrahedral mesh (Barbic & James 2005).\n"
               "Writes NAME.qvr (the runtime model; formats/model/QVR.md), NAME.h5 (every stage; formats/ARCHIVE.md)\n"
               "and NAME.xmf (ParaView).\n"
               "PETSc/SLEPc options pass through: -factor_* (the Cholesky factors), -eps_tol, -eps_ncv, -st_* (--eigensolver krylov-schur), -log_view, ..."};
  app::MeshOptions meshOptions;
  app::FixedVertexOptions fixedOptions;
  BakeSettings s;
  bool quiet = false;
  meshOptions.addTo(app, "Tetrahedral mesh (.msh .vtk .vtu .mesh .veg .node/.ele) or a closed triangle surface "
                         "(.obj .gltf .glb .stl .ply .fbx .off ...), tetrahedralized by gmsh into NAME.tets.vtu");
  fixedOptions.addTo(app);
  app.add_option("--tets", s.surface.mesher.targetTets, "A surface input: about this many tets")
      ->check(app::Positive)->capture_default_str();
  app.add_option("--edge", s.surface.mesher.edgeLength, "A surface input: tet edge length in m (instead of --tets)")
      ->check(app::Positive);
  app.add_option("--min-dihedral", s.surface.mesher.minDihedral,
                 "A surface input: the smallest dihedral angle every tet must reach, degrees (checked)")
      ->check(app::Between(0.0, 60.0))->capture_default_str();
  app.add_option("--mesher-time-limit", s.surface.mesher.timeLimit,
                 "A surface input: seconds each gmsh run may take before the bake stops")
      ->check(app::Positive)->capture_default_str();
  app.add_flag("--no-fill-holes{false}", s.surface.checks.fillHoles,
               "A surface input: refuse holes instead of closing each with a fan around its centre");
  app.add_option("--render-mesh", s.surface.renderMesh,
                 "Triangle mesh drawn in place of the tets' surface, each vertex bound to its tet (default: the input "
                 "when it is a surface); stored in NAME.qvr with its normals and UVs");
  app.add_option("--embed-tolerance", s.surface.embedTolerance,
                 "How far (m) outside the tets a render vertex may lie (default: two mean tet edges or a tenth of the render mesh's diagonal, the larger)")
      ->check(app::Positive);
  app.add_option("--E", s.mesh.material.youngsModulus, "Young's modulus in Pa (> 0); overrides the mesh file's materials");
  app.add_option("--nu", s.mesh.material.poissonRatio, "Poisson ratio in (-1, 0.5); overrides the mesh file's materials");
  app.add_option("--density", s.mesh.material.density, "Density in kg/m^3 (> 0); overrides the mesh file's materials");
  app.add_option("--modes", s.modes, "Linear modes k (the six rigid modes of a free object are not counted)")
      ->capture_default_str();
  std::vector<std::string> solvers;
  for (Eigensolver solver : {Eigensolver::Block, Eigensolver::KrylovSchur}) solvers.push_back(eigensolverName(solver));
  app.add_option_function<std::string>(
         "--eigensolver",
         [&s](const std::string& name) {
           for (Eigensolver solver : {Eigensolver::Block, Eigensolver::KrylovSchur})
             if (name == eigensolverName(solver)) s.eigensolver = solver;
         },
         "How the modes are found: block (block Krylov-Schur, blocks of solves; default) or krylov-schur (SLEPc's, "
         "one solve at a time; its -eps_* and -st_* options apply)")
      ->check(CLI::IsMember(solvers));
  app.add_option("--rank", s.basis.settings.rank, "Basis vectors r, at most the free DOFs; fewer (with a warning) where --basis yields fewer")
      ->capture_default_str();
  std::vector<std::string> kinds;
  for (BasisKind kind : {BasisKind::Pca, BasisKind::KeepModes, BasisKind::Modes}) kinds.push_back(basisKindName(kind));
  app.add_option_function<std::string>(
         "--basis",
         [&s](const std::string& name) {
           for (BasisKind kind : {BasisKind::Pca, BasisKind::KeepModes, BasisKind::Modes})
             if (name == basisKindName(kind)) s.basis.settings.kind = kind;
         },
         "pca: mass-PCA of the weighted modes and derivatives (Barbic & James); keep-modes: the k modes exactly, then "
         "derivatives; modes: the first r modes (precompute/stages/basis.h says what each buys)")
      ->check(CLI::IsMember(kinds))
      ->default_str("pca");
  app.add_option("--pca-amplitude", s.basis.settings.pcaAmplitude,
                 "pca: the amplitude the derivatives are weighed at, a fraction of the object's extent "
                 "||X - c||_M = sqrt(mass) x its radius of gyration: larger holds large deformations better, smaller "
                 "more of the baked frequencies")
      ->check(app::Between(1e-3, 1e3))
      ->capture_default_str();
  app.add_flag("--exact-rank", s.basis.settings.exactRank, "Fail rather than bake fewer than --rank vectors");
  app.add_option("--basis-from", s.basis.userBasis,
                 "Use this basis instead of modes + derivatives: FILE.npy or FILE.h5:/dataset, shape (3 x vertices, r) "
                 "in the mesh file's vertex order");
  app.add_option("--basis-precision", s.output.model.basisPrecision, "Bits per basis entry in NAME.qvr: 32 or 64")
      ->capture_default_str();
  app.add_option("--damping-ratio", s.output.model.dampingRatio,
                 "Default damping stored in NAME.qvr: fraction of critical at the first mode (stiffness-proportional)")
      ->check(app::NonNegative)
      ->capture_default_str();
  app.add_option("--time-step", s.output.model.timeStep, "Suggested time step stored in NAME.qvr, in s")
      ->check(app::TimeStep)
      ->capture_default_str();
  app.add_option("--fidelity-max-tets", s.fidelity.maxTets,
                 "Run the fidelity report only on meshes of at most this many tets (larger: skipped, saying so)")
      ->check(app::NonNegative)
      ->capture_default_str();
  app.add_flag("--no-fidelity{false}", s.fidelity.enabled,
               "Skip the fidelity report (the reduced model against full-space StVK on static loads: serial, the "
               "slowest stage on large meshes)");
  app.add_flag("--export-npy", s.output.exportNpy, "Also write NAME.eigenvalues.npy, NAME.modes.npy and NAME.U.npy (float64)");
  app.add_option("--threads", s.threads,
                 "Threads per rank of the polynomial stage (default: the cores the rank may run on, shared among "
                 "the ranks of its machine; mpirun binds each rank to one core). The results do not depend on it")
      ->check(app::Positive);
  app.add_flag("--resume", s.resume, "Reuse the stages of NAME.h5.partial (or NAME.h5) whose inputs have not changed");
  app.add_option("-o,--output", s.output.name, "Output name: writes NAME.qvr, NAME.h5 and NAME.xmf")
      ->required()
      ->transform(app::OutputName({".qvr", ".h5", ".xmf"}));
  app.add_flag("--quiet", quiet, "Print nothing but warnings and errors");

  std::vector<char*> ownArgv;
  for (auto& a : own) ownArgv.push_back(a.data());
  try {
    app.parse(static_cast<int>(ownArgv.size()), ownArgv.data());
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  for (int i = 0; i < argc; ++i) s.commandLine += (i ? " " : "") + std::string(argv[i]);
  for (size_t i = 1; i < petsc.size(); ++i) s.petscOptions += (i > 1 ? " " : "") + petsc[i];
  // PETSc also reads options from the environment: they change results as much as the command line's.
  if (const char* fromEnvironment = std::getenv("PETSC_OPTIONS"); fromEnvironment && *fromEnvironment) {
    s.petscOptions += std::string(s.petscOptions.empty() ? "" : " ") + fromEnvironment;
    s.commandLine = "PETSC_OPTIONS='" + std::string(fromEnvironment) + "' " + s.commandLine;
  }
  s.mesh.path = meshOptions.path;
  s.mesh.checks = meshOptions.checks;

  BakeContext ctx(petsc);
  ctx.quiet = quiet;
  ctx.progress(blas);
  if (isTetMeshPath(s.mesh.path) && ctx.rank() == 0)
    for (const char* surfaceOnly : {"--tets", "--edge", "--min-dihedral", "--mesher-time-limit", "--no-fill-holes"})
      if (app.count(surfaceOnly) > 0)
        std::cerr << "quiver-bake: warning: " << surfaceOnly << " applies to a surface input; " << s.mesh.path
                  << " is a tet mesh: ignored\n";
  if (app.count("--pca-amplitude") > 0 && (s.basis.settings.kind != BasisKind::Pca || !s.basis.userBasis.empty()) &&
      ctx.rank() == 0)
    std::cerr << "quiver-bake: warning: --pca-amplitude applies to the pca recipe, not to "
              << (s.basis.userBasis.empty() ? "--basis " + std::string(basisKindName(s.basis.settings.kind))
                                            : "--basis-from")
              << ": ignored\n";
  std::string error;
  try {
    checkBakeSettings(s);  // before any work
    s.mesh.fixed = fixedOptions.resolved();
    runBake(ctx, s);
  } catch (const Interrupted& e) {
    // gmsh is stopped and the stack unwound, its temporary folder with it: end as signalled, with
    // no agreeing on an error (the other ranks had the signal too, or mpirun stops them).
    std::cerr << "quiver-bake: " << e.what() << std::endl;
    std::signal(e.signal, SIG_DFL);
    std::raise(e.signal);
    return 128 + e.signal;  // were it blocked in this thread
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
