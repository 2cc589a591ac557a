#include "precompute/bake.h"

#include <ctime>
#include <filesystem>
#include <memory>

#include <hdf5.h>
#include <mpi.h>
#include <petscsys.h>
#include <slepcsys.h>

#include "formats/model/qvr.h"
#include "precompute/archive/xdmf.h"
#include "precompute/rigid_modes.h"
#include "precompute/stage_runner.h"
#include "precompute/stages/assemble.h"
#include "precompute/stages/fidelity.h"
#include "precompute/stages/partition.h"

#ifndef QUIVER_VERSION
#error "the build defines QUIVER_VERSION (the CMake project's version)"
#endif

extern "C" char* openblas_get_config(void);  // OpenBLAS's own, not in its cblas.h
extern "C" char* openblas_get_corename(void);

namespace quiver {

namespace fs = std::filesystem;

namespace {

std::string isoNow() {
  std::time_t t = std::time(nullptr);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&t));
  return buf;
}

// What computed the numbers, for /provenance: the same inputs on other versions may differ in
// their last bits.
std::string libraryVersions() {
  char petsc[128], slepc[128], mpi[MPI_MAX_LIBRARY_VERSION_STRING];
  PetscGetVersion(petsc, sizeof petsc);
  SlepcGetVersion(slepc, sizeof slepc);
  int length = 0;
  MPI_Get_library_version(mpi, &length);
  std::string mpiLine(mpi, static_cast<size_t>(length));
  mpiLine = mpiLine.substr(0, mpiLine.find_first_of(",\n"));
  unsigned major = 0, minor = 0, release = 0;
  H5get_libversion(&major, &minor, &release);
  std::string blas = openblas_get_config();
  std::string petscLine = petsc;
  petscLine.erase(petscLine.find_last_not_of(' ') + 1);
  return petscLine + "; " + slepc + "; HDF5 " + std::to_string(major) + "." + std::to_string(minor) + "." +
         std::to_string(release) + "; " + mpiLine + "; " + blas.substr(0, blas.find(' ', blas.find(' ') + 1)) +
         " (core " + openblas_get_corename() + ")";
}

std::string partialPath(const BakeSettings& s) { return s.output.name + ".h5.partial"; }

// NAME.h5.partial until the bake completes; --resume starts from it, or from a finished NAME.h5.
std::unique_ptr<Archive> openArchive(const BakeContext& ctx, const BakeSettings& s) {
  const std::string finalPath = s.output.name + ".h5";
  bool reuse = false;
  if (s.resume) {
    if (fs::exists(partialPath(s))) {
      reuse = true;
    } else if (fs::exists(finalPath)) {
      ctx.onRankZero([&] { fs::copy_file(finalPath, partialPath(s), fs::copy_options::overwrite_existing); });
      reuse = true;
    }
  }
  auto archive = std::make_unique<Archive>(ctx.comm(), partialPath(s), reuse ? Archive::Mode::ReadWrite : Archive::Mode::Create);
  archive->setAttribute("/", "format", std::string("quiver bake archive"));
  archive->setAttribute("/", "schema_version", static_cast<int64_t>(1));
  archive->setAttribute("/", "quiver_version", std::string(bakeVersion()));
  return archive;
}

// Provenance, the XDMF index of the vector fields, then NAME.h5.partial becomes NAME.h5.
void finishArchive(const BakeContext& ctx, const BakeSettings& s, Archive& archive, const StageRunner& stages,
                   const MeshInputs& in, int modeCount, int derivativeCount, int r) {
  archive.createGroup("/provenance");
  archive.setAttribute("/provenance", "quiver_version", std::string(bakeVersion()));
  archive.setAttribute("/provenance", "command_line", s.commandLine);
  archive.setAttribute("/provenance", "ranks", static_cast<int64_t>(ctx.size()));
  archive.setAttribute("/provenance", "created", isoNow());
  archive.setAttribute("/provenance", "libraries", libraryVersions());
  archive.setAttribute("/provenance", "mesh_hash", in.hash);
  for (const auto& [stage, seconds] : stages.all()) archive.setAttribute("/provenance", stage + "_seconds", seconds);
  archive.flush();
  std::vector<std::pair<std::string, int64_t>> fields = {{"/modes/vectors", modeCount}};
  if (derivativeCount > 0) fields.emplace_back("/derivatives/vectors", derivativeCount);
  fields.emplace_back("/basis/vectors", r);
  const std::string h5Name = fs::path(s.output.name + ".h5").filename().string();
  ctx.onRankZero([&] { writeModesXdmf(s.output.name + ".xmf", h5Name, in.mesh.mesh.vertexCount(), in.mesh.mesh.tetCount(), fields); });
  archive.close();
  ctx.onRankZero([&] { fs::rename(partialPath(s), s.output.name + ".h5"); });
}

} // namespace

const char* bakeVersion() { return QUIVER_VERSION; }

void checkBakeSettings(const BakeSettings& s) {
  Material check = s.mesh.fallback;
  if (s.mesh.material.youngsModulus) check.youngsModulus = *s.mesh.material.youngsModulus;
  if (s.mesh.material.poissonRatio) check.poissonRatio = *s.mesh.material.poissonRatio;
  if (s.mesh.material.density) check.density = *s.mesh.material.density;
  if (std::string bad = checkMaterial(check); !bad.empty()) throw std::invalid_argument(bad);
  if (s.modes < 1) throw std::invalid_argument("--modes must be at least 1");
  if (s.basis.settings.rank < 1) throw std::invalid_argument("--rank must be at least 1");
  if (!(s.basis.settings.pcaAmplitude > 0 && std::isfinite(s.basis.settings.pcaAmplitude)))
    throw std::invalid_argument("--pca-amplitude must be finite and > 0");
  const int candidates =
      s.basis.settings.kind == BasisKind::Modes ? s.modes : s.modes + s.modes * (s.modes + 1) / 2;
  if (s.basis.userBasis.empty() && s.basis.settings.exactRank && s.basis.settings.rank > candidates)
    throw std::invalid_argument("--rank " + std::to_string(s.basis.settings.rank) + " exceeds the " +
                                std::to_string(candidates) + " vectors that --basis " +
                                basisKindName(s.basis.settings.kind) + " makes of " + std::to_string(s.modes) +
                                " modes; raise --modes or drop --exact-rank");
  if (s.output.name.empty()) throw std::invalid_argument("-o NAME is required");
  if (s.output.model.basisPrecision != 32 && s.output.model.basisPrecision != 64)
    throw std::invalid_argument("--basis-precision must be 32 or 64");
  if (!(s.output.model.dampingRatio >= 0 && std::isfinite(s.output.model.dampingRatio)))
    throw std::invalid_argument("--damping-ratio must be finite and >= 0");
  if (!(s.output.model.timeStep >= kSmallestTimeStep && std::isfinite(s.output.model.timeStep)))
    throw std::invalid_argument("--time-step must be finite and at least 1e-12 s");
  const fs::path folder = fs::path(s.output.name).parent_path();
  if (!folder.empty() && !fs::is_directory(folder))
    throw std::invalid_argument("output folder '" + folder.string() + "' does not exist");
  // Found only at the end, a folder in an output's place failed the last rename after the others.
  for (const char* suffix : {".qvr", ".h5", ".h5.partial", ".xmf"})
    if (fs::is_directory(s.output.name + suffix))
      throw std::invalid_argument("output '" + s.output.name + suffix + "' is a folder");
}

void runBake(const BakeContext& ctx, const BakeSettings& s) {
  checkBakeSettings(s);
  StageRunner stages(ctx, s.resume);
  MeshSettings meshSettings = s.mesh;
  if (!isTetMeshPath(s.mesh.path)) meshSettings.path = meshSurface(ctx, s.mesh.path, s.surface, s.output.name);
  const MeshInputs in = stages.run("mesh", [&] { return loadMeshInputs(meshSettings); });
  warnAboutMesh(ctx, in, s.mesh);  // names the file the user gave, not the tets meshed from it
  const RenderInputs render = bindRenderMesh(ctx, s.mesh.path, s.surface, in.mesh.mesh);
  // An eigensolver needs more DOFs than modes (k at the free DOFs leaves it no room to iterate).
  if (s.modes + (in.freeObject() ? 6 : 0) >= in.freeDofs || s.basis.settings.rank > in.freeDofs)
    throw std::invalid_argument("the mesh has " + std::to_string(in.freeDofs) + " free DOFs: too few for --modes " +
                                std::to_string(s.modes) + (in.freeObject() ? " (+ 6 rigid)" : "") + " and --rank " +
                                std::to_string(s.basis.settings.rank));
  stages.report(describeMesh(in));
  // A user basis is read before any work: a wrong one once failed only after the modes.
  Eigen::MatrixXd userBasis;
  if (!s.basis.userBasis.empty()) {
    std::string error;
    try {
      userBasis = loadUserBasis(ctx.comm(), s.basis.userBasis, in.mesh);
    } catch (const std::exception& e) {
      error = e.what();
    }
    throwIfAnyRankFailed(error, ctx.comm());
  }
  const Partition partition = stages.run("partition", [&] { return partitionMesh(in.mesh.mesh, {ctx.size()}); });
  stages.report(std::to_string(ctx.size()) + " part(s), " + std::to_string(partition.cutFaces) + " cut faces");

  const std::unique_ptr<Archive> archive = openArchive(ctx, s);
  stages.setArchive(archive.get());
  writeMeshInputs(*archive, in, s.mesh.path);
  writePartition(*archive, partition, ctx.size());
  const DofLayout layout(ctx.comm(), partition.vertexPart, in.fixed);
  const AssembledSystem system =
      stages.run("assemble", [&] { return assembleSystem(in.mesh.mesh, in.perTet, layout); });
  stages.report("K and M of " + std::to_string(layout.globalDofs()) + " DOFs");
  const Eigen::MatrixXd rigid = in.freeObject() ? rigidModes(in.mesh.mesh, system.mass, layout) : Eigen::MatrixXd();

  // K's factor, shared by the modes (at shift 0) and the derivatives of a fixed object.
  StiffnessFactor stiffnessFactor(system.stiffness, layout);
  const std::string modesHash = modesInputHash(in.hash, s.modes, s.eigensolver, s.petscOptions);
  const LinearModes modes =
      modesStage(stages, ctx, system, layout, rigid, s.modes, s.eigensolver, stiffnessFactor, modesHash);
  const bool derived = s.basis.userBasis.empty() && s.basis.settings.kind != BasisKind::Modes;
  const std::string derivativesHash = derivativesInputHash(modesHash);
  const ModalDerivatives derivatives =
      derived ? derivativesStage(stages, ctx, in.mesh.mesh, in.perTet, system, layout, modes, rigid,
                                 stiffnessFactor, derivativesHash)
              : ModalDerivatives{};
  stiffnessFactor.release();  // a copy of K and its factor per rank: not kept through the later stages
  const std::string basisHash = s.basis.userBasis.empty()
                                    ? basisInputHash(derived ? derivativesHash : modesHash, s.basis.settings)
                                    : userBasisInputHash(in.hash, s.basis.userBasis);
  const bool pca = s.basis.userBasis.empty() && s.basis.settings.kind == BasisKind::Pca;
  const ReducedBasis basis = stages.run("basis", [&] {
    return bakeBasis(ctx, s.basis, userBasis, system.mass, layout, modes, derivatives,
                     pca ? objectExtent(in.mesh.mesh, in.perTet) : 0.0, *archive, basisHash);
  });
  stages.report(describeBasis(basis));

  const Eigen::MatrixXd fullU = layout.gatherToAll(basis.vectors);
  const EnergyPolynomial energy =
      polynomialStage(stages, ctx, in.mesh.mesh, in.perTet, partition.tetPart, fullU, polynomialInputHash(basisHash),
                      s.threads > 0 ? s.threads : ctx.coresPerRank());
  const bool small = in.mesh.mesh.tetCount() <= s.fidelity.maxTets;
  if (s.fidelity.enabled && !small)
    ctx.progress("fidelity: skipped: " + std::to_string(in.mesh.mesh.tetCount()) + " tets is above --fidelity-max-tets " +
                 std::to_string(s.fidelity.maxTets) + " (its full-space solves are serial: about 16 s at 33k tets, longer beyond)");
  const bool fidelityRuns = s.fidelity.enabled && small;
  // A resumed archive may hold an earlier bake's report: the .qvr will have none, nor may the archive.
  if (!fidelityRuns && archive->exists("/fidelity")) archive->removeObject("/fidelity");
  const FidelityReport fidelity = fidelityRuns ? fidelityStage(stages, ctx, in, fullU, modes, *archive) : FidelityReport{};
  const std::string qvr = stages.run("export", [&] {
    return exportModel(ctx, s.output, in, layout, modes, fullU, energy, fidelity, render);
  });
  stages.report(qvr);

  finishArchive(ctx, s, *archive, stages, in, static_cast<int>(modes.vectors.cols()),
                static_cast<int>(derivatives.vectors.cols()), static_cast<int>(basis.vectors.cols()));
  ctx.progress("wrote " + qvr + ", " + s.output.name + ".h5 and " + s.output.name + ".xmf");
  ctx.warnUnusedOptions();
}

} // namespace quiver
