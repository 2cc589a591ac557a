#include "precompute/stages/export_model.h"

#include "common/mass_matrix.h"
#include "formats/npy.h"

namespace quiver {

namespace {

// 3N x cols in the input file's vertex order (zeros for vertices the loader dropped), row-major.
std::vector<double> inFileOrder(const Eigen::MatrixXd& full, const CheckedMesh& mesh) {
  const int64_t cols = full.cols();
  std::vector<double> out(3 * mesh.loadedVertex.size() * cols, 0.0);
  for (size_t v = 0; v < mesh.fileVertex.size(); ++v)
    for (int c = 0; c < 3; ++c)
      for (int64_t j = 0; j < cols; ++j) out[(3 * mesh.fileVertex[v] + c) * cols + j] = full(3 * v + c, j);
  return out;
}

} // namespace

std::string exportModel(const BakeContext& ctx, const ExportRequest& request, const MeshInputs& in,
                        const DofLayout& layout, const LinearModes& modes,
                        const Eigen::MatrixXd& fullU, const EnergyPolynomial& energy, const FidelityReport& fidelity,
                        const RenderInputs& render) {
  // Gravity projection U^T M e_a: the reduced force of a unit acceleration along each axis. M is
  // the whole mesh's consistent mass: a free vertex also carries weight it shares with its fixed
  // neighbours, which the assembled free-DOF matrix leaves out (2% of the sag on a 3-cell beam).
  // The rows of a consistent mass matrix sum to the lumped masses, so M e_a is the lumped M's
  // (which assembles 12 entries a tet instead of 144).
  const Eigen::SparseMatrix<double> wholeMass = lumpedMassMatrix(in.mesh.mesh, in.perTet);
  Eigen::MatrixXd axes = Eigen::MatrixXd::Zero(wholeMass.rows(), 3);
  for (Eigen::Index i = 0; i < axes.rows(); ++i) axes(i, i % 3) = 1;
  const Eigen::MatrixXd gravity = fullU.transpose() * (wholeMass * axes);
  ExportSettings settings = request.model;
  settings.rigidBody = in.freeObject();  // what a free object needs to fly
  ModelContents contents =
      makeModelContents(in.mesh, in.perTet, fullU, energy.coefficients, modes.eigenvalues, gravity, settings);
  for (const FidelityCase& c : fidelity.cases)
    contents.fidelityCases.push_back({c.name, c.error, c.largestDisplacement});
  contents.fidelityFrequencyErrors = fidelity.frequencyErrors;
  if (!render.path.empty()) contents.render = makeRenderMesh(render.render, in.mesh.mesh, render.embedding, fullU);
  const std::string path = request.name + ".qvr";
  ctx.onRankZero([&] { writeModelFile(path, contents); });
  if (request.exportNpy) {
    const Eigen::MatrixXd fullModes = layout.gatherToAll(modes.vectors);
    ctx.onRankZero([&] {
      const int64_t rows = 3 * static_cast<int64_t>(in.mesh.loadedVertex.size());
      writeNpy(request.name + ".eigenvalues.npy", {static_cast<int64_t>(modes.eigenvalues.size())},
               modes.eigenvalues.data());
      writeNpy(request.name + ".modes.npy", {rows, fullModes.cols()}, inFileOrder(fullModes, in.mesh).data());
      writeNpy(request.name + ".U.npy", {rows, fullU.cols()}, inFileOrder(fullU, in.mesh).data());
    });
  }
  return path;
}

} // namespace quiver
