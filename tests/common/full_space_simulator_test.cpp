// The full-space reference simulator: energy conservation without damping, the four sparse solvers
// giving one trajectory, and damped motion settling on the static equilibrium of a separate solve.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <Eigen/SparseCholesky>

#include <algorithm>
#include <cstdio>
#include <map>

#include "common/box_mesh.h"
#include "common/full_space_simulator.h"
#include "common/mass_matrix.h"

using namespace quiver;

namespace {

struct Bar {
  TetMesh mesh = makeBoxMesh({0.4, 0.05, 0.05}, {8, 1, 1});
  std::vector<Material> perTet;
  std::vector<int> fixed, tip;
  Bar() {
    Material m;
    m.youngsModulus = 1e6;
    m.poissonRatio = 0.35;
    perTet.assign(mesh.tets.size(), m);
    for (int v = 0; v < mesh.vertexCount(); ++v) {
      if (mesh.vertices[v].x() == 0) fixed.push_back(v);
      if (mesh.vertices[v].x() > 0.4 - 1e-9) tip.push_back(v);
    }
  }
  void pull(FullSpaceSimulator& sim, double newtons) const {
    for (int v : tip) sim.addVertexForce(v, Eigen::Vector3d(0, 0, -newtons / tip.size()));
  }
};

} // namespace

TEST(FullSpaceSimulator, UndampedNewmarkConservesEnergy) {
  Bar bar;
  FullSpaceSettings s;
  s.timeStep = 2e-3;
  s.newtonTolerance = 1e-10;
  FullSpaceSimulator sim(bar.mesh, bar.perTet, bar.fixed, s);
  for (int step = 0; step < 30; ++step) {
    bar.pull(sim, 0.5);  // about 1% of the length at the tip
    sim.step();
  }
  // The step after the release still averages the last loaded acceleration (the trapezoidal rule
  // spreads a force over half a step on each side): energy is conserved from the next one on.
  sim.step();
  const double initial = sim.kineticEnergy() + sim.elasticEnergy();
  double worst = 0;
  for (int step = 0; step < 1000; ++step) {
    sim.step();
    worst = std::max(worst, std::abs(sim.kineticEnergy() + sim.elasticEnergy() - initial) / initial);
  }
  // Exact for a linear system; StVK's nonlinearity at this amplitude costs a few parts in 1e5.
  EXPECT_LT(worst, 1e-4);
  RecordProperty("energy_drift", std::to_string(worst));
}

TEST(FullSpaceSimulator, FourSolversGiveOneTrajectory) {
  Bar bar;
  std::vector<Eigen::VectorXd> finals;
  for (const char* name : {"ldlt", "llt", "cg", "lu"}) {
    FullSpaceSettings s;
    s.solver = parseSparseSolver(name);
    s.rayleighBeta = 1e-3;
    FullSpaceSimulator sim(bar.mesh, bar.perTet, bar.fixed, s);
    for (int step = 0; step < 40; ++step) {
      if (step < 20) bar.pull(sim, 1.0);
      sim.step();
    }
    finals.push_back(sim.displacement());
  }
  for (size_t k = 1; k < finals.size(); ++k)
    EXPECT_LT((finals[k] - finals[0]).norm(), 1e-8 * finals[0].norm()) << "solver " << k;
  EXPECT_GT(finals[0].norm(), 1e-3);
  EXPECT_THROW(parseSparseSolver("qr"), std::invalid_argument);
}

TEST(FullSpaceSimulator, DampedMotionSettlesOnTheStaticEquilibrium) {
  Bar bar;
  FullSpaceSettings s;
  s.rayleighAlpha = 30;
  s.newtonTolerance = 1e-10;
  FullSpaceSimulator sim(bar.mesh, bar.perTet, bar.fixed, s);
  sim.setGravity(Eigen::Vector3d(0, 0, -9.81));
  for (int step = 0; step < 2400; ++step) sim.step();
  // Static Newton solve of R(u) = M g on the free DOFs, written here from the force model alone.
  StVKForceModel model(bar.mesh, bar.perTet);
  const int n = model.dofCount();
  std::vector<int> free;
  for (int d = 0; d < n; ++d)
    if (std::find(bar.fixed.begin(), bar.fixed.end(), d / 3) == bar.fixed.end()) free.push_back(d);
  Eigen::VectorXd u = Eigen::VectorXd::Zero(n), R, g(n);
  for (int d = 0; d < n; ++d) g[d] = d % 3 == 2 ? -9.81 : 0;
  const Eigen::VectorXd f = [&] {
    Eigen::VectorXd out(n);
    Eigen::SparseMatrix<double> M = consistentMassMatrix(bar.mesh, bar.perTet);
    out = M * g;
    return out;
  }();
  for (int it = 0; it < 30; ++it) {
    model.internalForce(u, R);
    const Eigen::MatrixXd K = Eigen::MatrixXd(model.tangentStiffness(u))(free, free);
    const Eigen::VectorXd r = (R - f)(free);
    u(free) -= K.ldlt().solve(r);
  }
  EXPECT_LT((sim.displacement() - u).norm(), 1e-6 * u.norm());
}

// Linear elasticity and modal warping in full space: at a tiny load they agree with StVK; at a
// large one linear displacements stretch the bar's centre line and warping keeps its length.
TEST(FullSpaceSimulator, LinearAndWarpedElasticity) {
  Bar bar;
  auto settle = [&](qv_elasticity elasticity, double newtons) {
    FullSpaceSettings s;
    s.elasticity = elasticity;
    s.rayleighAlpha = 40;
    s.newtonTolerance = 1e-10;
    FullSpaceSimulator sim(bar.mesh, bar.perTet, bar.fixed, s);
    for (int step = 0; step < 1500; ++step) {
      bar.pull(sim, newtons);
      sim.step();
    }
    return sim.displacement();
  };
  // Length of the line through the cross-sections' centroids (the neutral axis), relative to 0.4 m.
  auto centreLine = [&](const Eigen::VectorXd& u) {
    std::map<double, std::pair<Eigen::Vector3d, int>> sections;
    for (int v = 0; v < bar.mesh.vertexCount(); ++v) {
      auto& [sum, count] = sections[bar.mesh.vertices[v].x()];
      if (count == 0) sum.setZero();
      sum += bar.mesh.vertices[v] + u.segment<3>(3 * v);
      ++count;
    }
    double length = 0;
    Eigen::Vector3d previous;
    bool first = true;
    for (const auto& [x, entry] : sections) {
      const Eigen::Vector3d centre = entry.first / entry.second;
      if (!first) length += (centre - previous).norm();
      previous = centre;
      first = false;
    }
    return length / 0.4 - 1;
  };
  const Eigen::VectorXd tinyStvk = settle(QV_ELASTICITY_STVK, 1e-3), tinyLinear = settle(QV_ELASTICITY_LINEAR, 1e-3),
                        tinyWarped = settle(QV_ELASTICITY_MODAL_WARPING, 1e-3);
  EXPECT_LT((tinyLinear - tinyStvk).norm(), 1e-3 * tinyStvk.norm());
  EXPECT_LT((tinyWarped - tinyLinear).norm(), 1e-3 * tinyLinear.norm());
  const double linear = centreLine(settle(QV_ELASTICITY_LINEAR, 12.0)), warped = centreLine(settle(QV_ELASTICITY_MODAL_WARPING, 12.0));
  EXPECT_GT(linear, 0.02);
  EXPECT_LT(std::abs(warped), 0.3 * linear);
  std::printf("full space, centre line under a large pull: linear %+.2f%%, warped %+.2f%%\n", 100 * linear, 100 * warped);
}

// A hard release: the free end twisted by 60 degrees with stiff springs, then let go, at 60 Hz.
// A single Newton solve from the last acceleration does not converge on the release step; the
// simulator halves the step until it does, and the motion stays finite and keeps its energy bounded.
TEST(FullSpaceSimulator, SubstepsThroughAHardRelease) {
  Bar bar;
  FullSpaceSettings s;
  s.rayleighBeta = 0.002;
  FullSpaceSimulator sim(bar.mesh, bar.perTet, bar.fixed, s);
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (int v : bar.tip) centre += bar.mesh.vertices[v];
  centre /= bar.tip.size();
  std::vector<Eigen::Vector3d> targets(bar.tip.size());
  int newton = 0;
  for (int step = 0; step < 120; ++step) {
    if (step < 60) {
      const Eigen::Matrix3d R = Eigen::AngleAxisd(M_PI / 3 * (step + 1) / 60, Eigen::Vector3d::UnitX()).toRotationMatrix();
      for (size_t k = 0; k < bar.tip.size(); ++k) targets[k] = centre + R * (bar.mesh.vertices[bar.tip[k]] - centre);
      sim.setSprings(bar.tip, targets, 1e4);
    } else if (step == 60) {
      sim.clearSprings();
    }
    ASSERT_NO_THROW(newton += sim.step()) << "step " << step;
  }
  EXPECT_TRUE(sim.displacement().allFinite());
  EXPECT_GT(newton, 0);
}
