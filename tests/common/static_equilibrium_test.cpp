// Static equilibria against what does not share their code: the linear solve at a tiny load, the
// full-space dynamic simulator damped to rest, and the subspace solver on a basis of every free DOF.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>
#include <Eigen/SparseCholesky>

#include "common/box_mesh.h"
#include "common/full_space_simulator.h"
#include "common/mass_matrix.h"
#include "common/static_equilibrium.h"

using namespace quiver;

namespace {

struct Cantilever {
  TetMesh mesh = makeBoxMesh(Eigen::Vector3d(1, 0.1, 0.1), {10, 2, 2});
  Material material;
  std::vector<Material> perTet;
  std::vector<int> fixed, tip;
  Cantilever() {
    material.youngsModulus = 1e6;
    material.poissonRatio = 0.4;
    material.density = 1000;
    perTet.assign(mesh.tets.size(), material);
    for (int v = 0; v < mesh.vertexCount(); ++v) {
      if (mesh.vertices[v].x() < 1e-9) fixed.push_back(v);
      if (mesh.vertices[v].x() > 1 - 1e-9) tip.push_back(v);
    }
  }
  Eigen::VectorXd weight(double g) const {
    Eigen::VectorXd e = Eigen::VectorXd::Zero(3 * mesh.vertexCount());
    for (int v = 0; v < mesh.vertexCount(); ++v) e[3 * v + 2] = -g;
    return consistentMassMatrix(mesh, perTet) * e;
  }
};

} // namespace

TEST(StaticEquilibrium, ATinyLoadGivesTheLinearSolution) {
  Cantilever c;
  const StVKForceModel model(c.mesh, c.perTet);
  StaticLoad load;
  load.force = c.weight(1e-4);
  const Eigen::VectorXd u = solveStatic(model, c.mesh.vertices, c.fixed, load);
  // K(0) u = f on the free DOFs, by a dense solve.
  const int n = model.dofCount();
  std::vector<int> freeDof;
  for (int i = 0; i < n; ++i)
    if (std::find(c.fixed.begin(), c.fixed.end(), i / 3) == c.fixed.end()) freeDof.push_back(i);
  const Eigen::MatrixXd K = Eigen::MatrixXd(model.tangentStiffness(Eigen::VectorXd::Zero(n)));
  Eigen::MatrixXd Kf(freeDof.size(), freeDof.size());
  Eigen::VectorXd ff(freeDof.size());
  for (size_t i = 0; i < freeDof.size(); ++i) {
    ff[i] = load.force[freeDof[i]];
    for (size_t j = 0; j < freeDof.size(); ++j) Kf(i, j) = K(freeDof[i], freeDof[j]);
  }
  const Eigen::VectorXd linear = Kf.ldlt().solve(ff);
  Eigen::VectorXd uf(freeDof.size());
  for (size_t i = 0; i < freeDof.size(); ++i) uf[i] = u[freeDof[i]];
  EXPECT_LT((uf - linear).norm(), 1e-5 * linear.norm());
  for (int v : c.fixed) EXPECT_EQ(u.segment<3>(3 * v).norm(), 0.0);
}

TEST(StaticEquilibrium, TheDampedDynamicSimulatorComesToRestThere) {
  Cantilever c;
  const StVKForceModel model(c.mesh, c.perTet);
  StaticLoad load;
  load.force = c.weight(9.81);  // its own weight: a tip deflection of a quarter of the length
  const Eigen::VectorXd u = solveStatic(model, c.mesh.vertices, c.fixed, load);
  FullSpaceSettings settings;
  settings.timeStep = 0.02;
  settings.rayleighAlpha = 60;  // overdamped: it creeps to rest
  FullSpaceSimulator sim(c.mesh, c.perTet, c.fixed, settings);
  sim.setGravity(Eigen::Vector3d(0, 0, -9.81));
  for (int step = 0; step < 2000; ++step) sim.step();
  const Eigen::VectorXd dynamic = sim.displacement();
  EXPECT_GT(u.norm(), 0.1);
  EXPECT_LT((dynamic - u).norm(), 1e-5 * u.norm());
}

TEST(StaticEquilibrium, TheSubspaceSolverOnEveryFreeDofIsTheFullSolver) {
  Cantilever c;
  const StVKForceModel model(c.mesh, c.perTet);
  // Twist the tip by 30 degrees about the beam's axis with stiff springs: large rotations.
  StaticLoad load;
  const Eigen::Vector3d centre(1, 0.05, 0.05);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(M_PI / 6, Eigen::Vector3d::UnitX()).toRotationMatrix();
  for (int v : c.tip) {
    load.springVertices.push_back(v);
    load.springTargets.push_back(centre + R * (c.mesh.vertices[v] - centre));
  }
  load.springStiffness = 1e5;
  load.force = Eigen::VectorXd::Zero(model.dofCount());
  const Eigen::VectorXd full = solveStatic(model, c.mesh.vertices, c.fixed, load);
  Eigen::MatrixXd U = Eigen::MatrixXd::Zero(model.dofCount(), model.dofCount() - 3 * static_cast<int>(c.fixed.size()));
  for (int i = 0, j = 0; i < model.dofCount(); ++i)
    if (std::find(c.fixed.begin(), c.fixed.end(), i / 3) == c.fixed.end()) U(i, j++) = 1;
  const Eigen::VectorXd reduced = solveStaticReduced(model, c.mesh.vertices, U, load);
  EXPECT_LT((reduced - full).norm(), 1e-7 * full.norm());
  // The tip turned most of the way: a real twist, not a small one.
  const Eigen::Vector3d corner = c.mesh.vertices[c.tip.back()] + full.segment<3>(3 * c.tip.back());
  const double turned = std::atan2((corner - centre).z(), (corner - centre).y()) -
                        std::atan2((c.mesh.vertices[c.tip.back()] - centre).z(), (c.mesh.vertices[c.tip.back()] - centre).y());
  EXPECT_GT(turned, 0.7 * M_PI / 6);
}

// The bake passes its own solver for the Newton systems: a dense one here gives the same
// equilibrium as the default simplicial LDLT, and is the one used.
TEST(StaticEquilibrium, AGivenSolverIsUsedForTheNewtonSystems) {
  Cantilever c;
  const StVKForceModel model(c.mesh, c.perTet);
  StaticLoad load;
  load.force = c.weight(9.81);
  int calls = 0;
  const SymmetricSolve dense = [&](const Eigen::SparseMatrix<double>& H, const Eigen::VectorXd& b, Eigen::VectorXd& x) {
    ++calls;
    const Eigen::LLT<Eigen::MatrixXd> llt{Eigen::MatrixXd(H)};
    if (llt.info() != Eigen::Success) return false;
    x = llt.solve(b);
    return true;
  };
  const Eigen::VectorXd simplicial = solveStatic(model, c.mesh.vertices, c.fixed, load);
  const Eigen::VectorXd given = solveStatic(model, c.mesh.vertices, c.fixed, load, {}, dense);
  EXPECT_GT(calls, 0);
  EXPECT_LT((given - simplicial).norm(), 1e-8 * simplicial.norm());
  EXPECT_GT(simplicial.norm(), 0.1);
}
