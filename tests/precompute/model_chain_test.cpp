// The whole chain a game relies on: bake (modes, polynomials) -> .qvr bytes -> runtime loader and
// evaluator, checked against the full-space FEM projection U^T R(Uq), U^T K(Uq) U on 1 or 2 ranks.
#include <gtest/gtest.h>

#include <random>

#include "common/box_mesh.h"
#include "common/stvk_force_model.h"
#include "common/mesh_checks.h"
#include "formats/model_contents.h"
#include "precompute/stages/assemble.h"
#include "precompute/stages/polynomials.h"
#include "precompute/stages/modes.h"
#include "precompute/stages/partition.h"
#include "quiver/quiver.h"

using namespace quiver;

namespace {

struct LoadedModel {
  qv_model* model = nullptr;
  std::vector<double> scratch;
  explicit LoadedModel(const std::string& bytes) {
    char message[512] = "";
    EXPECT_EQ(qv_model_load_memory(bytes.data(), bytes.size(), nullptr, nullptr, &model, message, sizeof message), QV_OK)
        << message;
    scratch.resize(qv_model_scratch_size(model) / sizeof(double) + 1);
  }
  ~LoadedModel() { qv_model_destroy(model); }
};

} // namespace

// A clamped bar, its first 6 modes as the basis: the runtime's K(0) must be diag(lambda), and at
// every q its force and stiffness must be the full-space model's, projected.
TEST(ModelChain, RuntimeEvaluatesTheFullSpaceProjection) {
  int size = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  CheckedMesh mesh;
  mesh.mesh = makeBoxMesh({0.5, 0.08, 0.12}, {8, 2, 2});
  for (int v = 0; v < mesh.mesh.vertexCount(); ++v) mesh.fileVertex.push_back(v);
  mesh.loadedVertex = mesh.fileVertex;
  std::vector<int> fixed;
  for (int v = 0; v < mesh.mesh.vertexCount(); ++v)
    if (mesh.mesh.vertices[v].x() == 0) fixed.push_back(v);
  std::vector<Material> perTet(mesh.mesh.tetCount());
  Partition part = partitionMesh(mesh.mesh, {size});
  DofLayout layout(MPI_COMM_WORLD, part.vertexPart, fixed);
  AssembledSystem sys = assembleSystem(mesh.mesh, perTet, layout);
  ModeSettings ms;
  ms.count = 6;
  LinearModes modes = computeLinearModes(sys.stiffness, sys.mass, layout, ms, Eigen::MatrixXd());
  const Eigen::MatrixXd U = layout.gatherToAll(modes.vectors);
  const EnergyPolynomial energy = computeEnergyPolynomial(MPI_COMM_WORLD, mesh.mesh, perTet, part.tetPart, U, {});
  ExportSettings settings;
  settings.basisPrecision = 64;
  const std::string bytes = formatModel(
      makeModelContents(mesh, perTet, U, energy.coefficients, modes.eigenvalues, Eigen::MatrixXd::Zero(6, 3), settings));
  LoadedModel loaded(bytes);
  ASSERT_NE(loaded.model, nullptr);
  const int r = 6;

  Eigen::MatrixXd K(r, r);
  Eigen::VectorXd f(r), q = Eigen::VectorXd::Zero(r);
  ASSERT_EQ(qv_model_evaluate(loaded.model, q.data(), nullptr, f.data(), K.data(), loaded.scratch.data()), QV_OK);
  const Eigen::Map<const Eigen::VectorXd> lambda(modes.eigenvalues.data(), r);
  EXPECT_LT((K - Eigen::MatrixXd(lambda.asDiagonal())).norm(), 1e-10 * lambda.norm());

  StVKForceModel full(mesh.mesh, perTet);
  std::mt19937 rng(3);
  std::normal_distribution<double> n(0, 1);
  for (int trial = 0; trial < 20; ++trial) {
    for (auto& x : q) x = n(rng);
    q *= std::pow(10.0, -4.0 + 4.0 * trial / 19.0) * 0.5 / (U * q).cwiseAbs().maxCoeff();  // up to the bar's length
    const Eigen::VectorXd u = U * q;
    Eigen::VectorXd R;
    full.internalForce(u, R);
    const Eigen::VectorXd fRef = U.transpose() * R;
    const Eigen::MatrixXd KRef = U.transpose() * full.tangentStiffness(u) * U;
    double e = 0;
    ASSERT_EQ(qv_model_evaluate(loaded.model, q.data(), &e, f.data(), K.data(), loaded.scratch.data()), QV_OK);
    EXPECT_LT((f - fRef).norm(), 1e-10 * fRef.norm()) << "trial " << trial;
    EXPECT_LT((K - KRef).norm(), 1e-10 * KRef.norm()) << "trial " << trial;  // row-major vs column-major: K is symmetric
    EXPECT_LT((K - K.transpose()).norm(), 1e-14 * K.norm());
    EXPECT_NEAR(e, full.energy(u), 1e-10 * full.energy(u));
  }

  // u = U q from the stored basis.
  std::vector<float> displacement(3 * mesh.mesh.vertexCount());
  ASSERT_EQ(qv_model_displacements(loaded.model, q.data(), displacement.data()), QV_OK);
  const Eigen::VectorXd u = U * q;
  for (int i = 0; i < u.size(); ++i) EXPECT_NEAR(displacement[i], u[i], 1e-6 * u.cwiseAbs().maxCoeff());
}
