#include "precompute/bake.h"

#include <chrono>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <sstream>

#include "formats/atomic_file.h"
#include "formats/mesh/read_mesh.h"
#include "formats/npy.h"
#include "precompute/archive/xdmf.h"
#include "precompute/checkpoint.h"
#include "precompute/distributed_dense.h"
#include "precompute/input_hash.h"
#include "precompute/rigid_modes.h"
#include "precompute/stages/assemble.h"
#include "quiver/quiver.h"

namespace quiver {

namespace fs = std::filesystem;

namespace {

class StageClock {
public:
  explicit StageClock(const BakeContext& ctx) : ctx_(ctx) {}
  // Runs `body` as stage `name`, recording its wall time (slowest rank's view: all ranks sync).
  template <class F>
  void run(const std::string& name, F&& body) {
    MPI_Barrier(ctx_.comm());
    const auto start = std::chrono::steady_clock::now();
    body();
    MPI_Barrier(ctx_.comm());
    seconds_.emplace_back(name, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  double last() const { return seconds_.back().second; }
  const std::vector<std::pair<std::string, double>>& all() const { return seconds_; }

private:
  const BakeContext& ctx_;
  std::vector<std::pair<std::string, double>> seconds_;
};

std::string fixed3(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

void hashMaterials(InputHash& h, const std::vector<Material>& perTet) {
  for (const Material& m : perTet) h.add(m.youngsModulus).add(m.poissonRatio).add(m.density);
}

// The user basis as a full 3n x r matrix in the loaded mesh's vertex order.
Eigen::MatrixXd loadUserBasis(const BakeContext& ctx, const std::string& spec, const CheckedMesh& mesh) {
  const int64_t fileRows = 3 * static_cast<int64_t>(mesh.loadedVertex.size());
  std::vector<int64_t> shape;
  std::vector<double> data;
  const size_t colon = spec.find(".h5:");
  if (colon != std::string::npos) {
    Archive user(ctx.comm(), spec.substr(0, colon + 3), Archive::Mode::ReadOnly);
    data = user.readReplicatedDouble(spec.substr(colon + 4), shape);
  } else {
    NpyArray a = readNpy(spec);
    shape = a.shape;
    data = std::move(a.data);
  }
  // (3N, r) as numpy users write it, or (r, N, 3) as the archive stores vectors; N in file order.
  const int64_t N = static_cast<int64_t>(mesh.loadedVertex.size());
  const bool columns = shape.size() == 2 && shape[0] == fileRows;
  const bool slices = shape.size() == 3 && shape[1] == N && shape[2] == 3;
  if (!columns && !slices)
    throw std::runtime_error(spec + ": a basis must have shape (3 x " + std::to_string(N) + " vertices, r) = (" +
                             std::to_string(fileRows) + ", r), or (r, " + std::to_string(N) + ", 3)");
  const int64_t r = columns ? shape[1] : shape[0];
  Eigen::MatrixXd full(3 * static_cast<int64_t>(mesh.fileVertex.size()), r);
  for (size_t v = 0; v < mesh.fileVertex.size(); ++v)
    for (int c = 0; c < 3; ++c) {
      const int64_t row = 3 * mesh.fileVertex[v] + c;
      for (int64_t j = 0; j < r; ++j) full(3 * v + c, j) = columns ? data[row * r + j] : data[j * fileRows + row];
    }
  return full;
}

// 3N x cols in the input file's vertex order (zeros for vertices the loader dropped), row-major.
std::vector<double> inFileOrder(const Eigen::MatrixXd& full, const CheckedMesh& mesh) {
  const int64_t cols = full.cols();
  std::vector<double> out(3 * mesh.loadedVertex.size() * cols, 0.0);
  for (size_t v = 0; v < mesh.fileVertex.size(); ++v)
    for (int c = 0; c < 3; ++c)
      for (int64_t j = 0; j < cols; ++j) out[(3 * mesh.fileVertex[v] + c) * cols + j] = full(3 * v + c, j);
  return out;
}

// A checkpointed stage: when resuming and the archive holds its results under the same input
// hash they are read back; otherwise they are computed and written. Returns whether they were reused.
template <class T, class Read, class Compute, class Write>
bool reuseOrCompute(bool resume, const Archive& archive, const std::string& group, const std::string& hash, T& out,
                    Read read, Compute compute, Write write) {
  if (resume && storedInputHash(archive, group) == hash) {
    out = read();
    return true;
  }
  out = compute();
  write(out);
  return false;
}

std::string isoNow() {
  std::time_t t = std::time(nullptr);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&t));
  return buf;
}

} // namespace

void checkBakeSettings(const BakeSettings& s) {
  Material check = s.fallback;
  if (s.material.youngsModulus) check.youngsModulus = *s.material.youngsModulus;
  if (s.material.poissonRatio) check.poissonRatio = *s.material.poissonRatio;
  if (s.material.density) check.density = *s.material.density;
  if (std::string bad = checkMaterial(check); !bad.empty()) throw std::invalid_argument(bad);
  if (s.modes < 1) throw std::invalid_argument("--modes must be at least 1");
  if (s.rank < 1) throw std::invalid_argument("--rank must be at least 1");
  const int candidates = s.basisKind == BasisKind::Modes ? s.modes : s.modes + s.modes * (s.modes + 1) / 2;
  if (s.basisFrom.empty() && s.exactRank && s.rank > candidates)
    throw std::invalid_argument("--rank " + std::to_string(s.rank) + " exceeds the " + std::to_string(candidates) +
                                " vectors that --basis " + basisKindName(s.basisKind) + " makes of " +
                                std::to_string(s.modes) + " modes; raise --modes or drop --exact-rank");
  if (s.output.empty()) throw std::invalid_argument("-o NAME is required");
  if (s.model.basisPrecision != 32 && s.model.basisPrecision != 64)
    throw std::invalid_argument("--basis-precision must be 32 or 64");
  if (!(s.model.dampingRatio >= 0)) throw std::invalid_argument("--damping-ratio must be >= 0");
  if (!(s.model.timeStep > 0)) throw std::invalid_argument("--time-step must be > 0 s");
  const fs::path folder = fs::path(s.output).parent_path();
  if (!folder.empty() && !fs::is_directory(folder))
    throw std::invalid_argument("output folder '" + folder.string() + "' does not exist");
}

void runBake(const BakeContext& ctx, const BakeSettings& s) {
  checkBakeSettings(s);
  StageClock clock(ctx);

  // Stage: mesh. Every rank reads and checks the same file, so every rank fails alike.
  CheckedMesh mesh;
  std::vector<int> fixed;
  std::vector<Material> perTet;
  std::string meshHash;
  clock.run("mesh", [&] {
    mesh = loadMesh(s.meshPath, s.checks);
    fixed = selectFixedVertices(mesh, s.fixed);
    perTet = resolveTetMaterials(mesh.mesh, s.fallback, s.material);
    for (const Material& m : perTet)
      if (std::string bad = checkMaterial(m); !bad.empty()) throw std::invalid_argument(s.meshPath + ": " + bad);
    InputHash h;
    h.add(readFileBytes(s.meshPath)).add(s.checks.fixOrientation).add(s.checks.degenerateTolerance).add(fixed);
    hashMaterials(h, perTet);
    meshHash = h.hex();
  });
  if (ctx.rank() == 0) {
    for (const std::string& w : mesh.warnings) std::fprintf(stderr, "quiver-bake: warning: %s\n", w.c_str());
    // A mesh without materials and a command line without all three values: say what is assumed.
    if (mesh.mesh.materials.empty() && !(s.material.youngsModulus && s.material.poissonRatio && s.material.density))
      std::fprintf(stderr,
                   "quiver-bake: warning: %s defines no material; using E = %g Pa, nu = %g, density = %g kg/m^3 "
                   "where --E, --nu, --density do not say\n",
                   s.meshPath.c_str(), perTet[0].youngsModulus, perTet[0].poissonRatio, perTet[0].density);
  }
  const int64_t freeDofs = 3 * (static_cast<int64_t>(mesh.mesh.vertexCount()) - static_cast<int64_t>(fixed.size()));
  const bool freeObject = fixed.empty();
  if (s.modes + (freeObject ? 6 : 0) > freeDofs || s.rank > freeDofs)
    throw std::invalid_argument("the mesh has " + std::to_string(freeDofs) + " free DOFs: too few for --modes " +
                                std::to_string(s.modes) + " and --rank " + std::to_string(s.rank));
  ctx.progress("mesh: " + std::to_string(mesh.mesh.vertexCount()) + " vertices, " +
               std::to_string(mesh.mesh.tetCount()) + " tets, " + std::to_string(fixed.size()) + " fixed vertices" +
               (freeObject ? " (free object: the six rigid modes are skipped)" : "") + ", " +
               std::to_string(freeDofs) + " free DOFs [" + fixed3(clock.last()) + " s]");

  Partition partition;
  clock.run("partition", [&] { partition = partitionMesh(mesh.mesh, {ctx.size()}); });
  ctx.progress("partition: " + std::to_string(ctx.size()) + " part(s), " + std::to_string(partition.cutFaces) +
               " cut faces [" + fixed3(clock.last()) + " s]");

  // The archive: NAME.h5.partial until the bake completes; --resume starts from it (or NAME.h5).
  const std::string finalPath = s.output + ".h5", partialPath = finalPath + ".partial";
  bool reuse = false;
  if (s.resume) {
    if (fs::exists(partialPath)) {
      reuse = true;
    } else if (fs::exists(finalPath)) {
      ctx.onRankZero([&] { fs::copy_file(finalPath, partialPath, fs::copy_options::overwrite_existing); });
      reuse = true;
    }
  }
  Archive archive(ctx.comm(), partialPath, reuse ? Archive::Mode::ReadWrite : Archive::Mode::Create);
  archive.setAttribute("/", "format", std::string("quiver bake archive"));
  archive.setAttribute("/", "schema_version", static_cast<int64_t>(1));
  archive.setAttribute("/", "quiver_version", std::string(qv_version_string()));
  writeInputs(archive, mesh, s.meshPath, perTet, fixed, partition, ctx.size());

  DofLayout layout(ctx.comm(), partition.vertexPart, fixed);
  AssembledSystem system;
  clock.run("assemble", [&] { system = assembleSystem(mesh.mesh, perTet, partition.tetPart, layout); });
  ctx.progress("assemble: K and M of " + std::to_string(layout.globalDofs()) + " DOFs [" + fixed3(clock.last()) + " s]");
  const Eigen::MatrixXd rigid = freeObject ? rigidModes(mesh.mesh, system.mass, layout) : Eigen::MatrixXd();

  const std::string modesHash = InputHash().add(meshHash).add(s.modes).add(s.petscOptions).hex();
  LinearModes modes;
  bool reused = false;
  clock.run("modes", [&] {
    reused = reuseOrCompute(
        reuse, archive, "/modes", modesHash, modes, [&] { return readModes(archive, layout); },
        [&] {
          ProgressMeter meter(ctx, "modes", "converged");
          ModeSettings settings;
          settings.count = s.modes;
          settings.progress = meter.callback();
          return computeLinearModes(system.stiffness, system.mass, layout, settings, rigid);
        },
        [&](const LinearModes& result) { writeModes(archive, result, layout, modesHash); });
  });
  const auto hz = modes.frequenciesHz();
  ctx.progress(std::string("modes: ") + (reused ? "reused, " : "") + std::to_string(s.modes) + " modes, " + fixed3(hz.front()) + " to " + fixed3(hz.back()) +
               " Hz, max residual " + fixed3(*std::max_element(modes.residuals.begin(), modes.residuals.end())) +
               " [" + fixed3(clock.last()) + " s]");
  for (size_t i = 0; i < hz.size(); ++i)
    ctx.progress("  mode " + std::to_string(i) + ": " + fixed3(hz[i]) + " Hz (lambda " + fixed3(modes.eigenvalues[i]) +
                 "), residual " + fixed3(modes.residuals[i]));

  ReducedBasis basis;
  std::string basisSource = s.basisKind == BasisKind::Pca ? "modes+derivatives" : basisKindName(s.basisKind);
  if (s.basisFrom.empty()) {
    // Version 2: residuals are normwise backward errors.
    const std::string derivativesHash = InputHash().add(modesHash).add(std::string("derivatives 2")).hex();
    ModalDerivatives derivatives;
    if (s.basisKind != BasisKind::Modes) {  // the modes-only basis needs none
    clock.run("derivatives", [&] {
      reused = reuseOrCompute(
          reuse, archive, "/derivatives", derivativesHash, derivatives, [&] { return readDerivatives(archive, layout); },
          [&] {
            ProgressMeter meter(ctx, "derivatives", "solved");
            DerivativeSettings settings;
            settings.progress = meter.callback();
            return computeModalDerivatives(mesh.mesh, perTet, partition.tetPart, system.stiffness, system.mass, layout,
                                           modes, rigid, settings);
          },
          [&](const ModalDerivatives& result) { writeDerivatives(archive, result, layout, derivativesHash); });
    });
    ctx.progress(std::string("derivatives: ") + (reused ? "reused, " : "") + std::to_string(derivatives.pairs.size()) +
                 " solved, max residual " +
                 fixed3(*std::max_element(derivatives.residuals.begin(), derivatives.residuals.end())) + " [" +
                 fixed3(clock.last()) + " s]");
    }
    clock.run("basis", [&] {
      BasisSettings settings;
      settings.rank = s.rank;
      settings.kind = s.basisKind;
      settings.exactRank = s.exactRank;
      basis = buildBasis(system.mass, layout, modes, derivatives, settings);
      InputHash hash;
      hash.add(derivativesHash).add(s.rank);
      if (s.basisKind != BasisKind::Pca) hash.add(basisSource);
      writeBasis(archive, basis, basisSource, layout, hash.hex());
    });
    if (!basis.warning.empty() && ctx.rank() == 0) std::fprintf(stderr, "quiver-bake: warning: %s\n", basis.warning.c_str());
  } else {
    basisSource = s.basisFrom;
    clock.run("basis", [&] {
      bool wasOrthonormal = true;
      const Eigen::MatrixXd full = loadUserBasis(ctx, s.basisFrom, mesh);
      basis = importBasis(system.mass, layout, layout.localRowsOf(full), wasOrthonormal);
      if (!wasOrthonormal) ctx.progress("warning: " + s.basisFrom + " was not M-orthonormal; it was orthonormalised");
      writeBasis(archive, basis, basisSource, layout, InputHash().add(meshHash).add(s.basisFrom).hex());
    });
  }
  ctx.progress("basis: r = " + std::to_string(basis.vectors.cols()) + ", max |U^T M U - I| = " +
               fixed3(basis.orthonormalityError) + " [" + fixed3(clock.last()) + " s]");

  const Eigen::MatrixXd fullU = layout.gatherToAll(basis.vectors);
  EnergyPolynomial energy;
  const std::string polynomialHash = InputHash().add(storedInputHash(archive, "/basis")).add(std::string("polynomials 1")).hex();
  clock.run("polynomials", [&] {
    reused = reuseOrCompute(
        reuse, archive, "/polynomials", polynomialHash, energy, [&] { return readPolynomial(archive); },
        [&] {
          ProgressMeter meter(ctx, "polynomials", "tets integrated (rank 0)");
          PolynomialSettings settings;
          settings.progress = meter.callback();
          return computeEnergyPolynomial(ctx.comm(), mesh.mesh, perTet, partition.tetPart, fullU, settings);
        },
        [&](const EnergyPolynomial& result) { writePolynomial(archive, result, polynomialHash); });
  });
  ctx.progress(std::string("polynomials: ") + (reused ? "reused, " : "") + std::to_string(energy.coefficients.size()) +
               " energy coefficients (exact, r = " + std::to_string(energy.r) + "), " +
               fixed3(1e6 * clock.last() / mesh.mesh.tetCount()) + " us per tet [" + fixed3(clock.last()) + " s]");

  clock.run("export", [&] {
    // Gravity projection U^T M e_a: the reduced force of a unit acceleration along each axis.
    Eigen::MatrixXd axes = Eigen::MatrixXd::Zero(layout.localDofs(), 3);
    for (Eigen::Index i = 0; i < axes.rows(); ++i) axes(i, i % 3) = 1;
    const Eigen::MatrixXd gravity = innerProducts(basis.vectors, multiply(system.mass, axes, layout), ctx.comm());
    const ModelContents contents = makeModelContents(mesh, perTet, fullU, energy.coefficients, modes.eigenvalues, gravity, s.model);
    ctx.onRankZero([&] { writeModelFile(s.output + ".qvr", contents); });
  });
  ctx.progress("export: " + s.output + ".qvr [" + fixed3(clock.last()) + " s]");

  if (s.exportNpy) {
    const Eigen::MatrixXd fullModes = layout.gatherToAll(modes.vectors);
    ctx.onRankZero([&] {
      const int64_t rows = 3 * static_cast<int64_t>(mesh.loadedVertex.size());
      writeNpy(s.output + ".eigenvalues.npy", {static_cast<int64_t>(modes.eigenvalues.size())}, modes.eigenvalues.data());
      writeNpy(s.output + ".modes.npy", {rows, fullModes.cols()}, inFileOrder(fullModes, mesh).data());
      writeNpy(s.output + ".U.npy", {rows, fullU.cols()}, inFileOrder(fullU, mesh).data());
    });
  }

  archive.createGroup("/provenance");
  archive.setAttribute("/provenance", "quiver_version", std::string(qv_version_string()));
  archive.setAttribute("/provenance", "command_line", s.commandLine);
  archive.setAttribute("/provenance", "ranks", static_cast<int64_t>(ctx.size()));
  archive.setAttribute("/provenance", "created", isoNow());
  archive.setAttribute("/provenance", "mesh_hash", meshHash);
  for (const auto& [stage, seconds] : clock.all()) archive.setAttribute("/provenance", stage + "_seconds", seconds);
  archive.flush();
  const std::string h5Name = fs::path(finalPath).filename().string();
  std::vector<std::pair<std::string, int64_t>> fields = {{"/modes/vectors", modes.vectors.cols()},
                                                         {"/basis/vectors", basis.vectors.cols()}};
  if (s.basisFrom.empty() && s.basisKind != BasisKind::Modes)
    fields.insert(fields.begin() + 1, {"/derivatives/vectors", s.modes * (s.modes + 1) / 2});
  ctx.onRankZero([&] { writeModesXdmf(s.output + ".xmf", h5Name, mesh.mesh.vertexCount(), mesh.mesh.tetCount(), fields); });
  archive.close();
  ctx.onRankZero([&] { fs::rename(partialPath, finalPath); });
  ctx.progress("wrote " + s.output + ".qvr, " + finalPath + " and " + s.output + ".xmf");
  ctx.warnUnusedOptions();
}

} // namespace quiver
