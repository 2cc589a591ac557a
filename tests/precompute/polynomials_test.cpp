// The reduced energy polynomial against the full-space FEM it reduces: for random q from tiny to
// large, its value, gradient and Hessian equal E(Uq), U^T R(Uq) and U^T K(Uq) U from common/.
// The polynomial is evaluated here term by term, from an enumeration of monomials written in this
// test (not the runtime's evaluator, which is tested against the same references elsewhere).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <mpi.h>
#include <random>

#include "common/box_mesh.h"
#include "common/reduced_energy.h"
#include "common/stvk_force_model.h"
#include "formats/model/qvr_writer.h"
#include "precompute/stages/partition.h"
#include "precompute/stages/polynomials.h"

using namespace quiver;

namespace {

struct Reference {
  double energy = 0;
  Eigen::VectorXd gradient;
  Eigen::MatrixXd hessian;
};

// Sorted index tuples of degree 2, 3, 4 in lexicographic order: the documented layout.
std::vector<std::vector<int>> monomials(int r) {
  std::vector<std::vector<int>> out;
  for (int i = 0; i < r; ++i)
    for (int j = i; j < r; ++j) out.push_back({i, j});
  for (int i = 0; i < r; ++i)
    for (int j = i; j < r; ++j)
      for (int k = j; k < r; ++k) out.push_back({i, j, k});
  for (int i = 0; i < r; ++i)
    for (int j = i; j < r; ++j)
      for (int k = j; k < r; ++k)
        for (int l = k; l < r; ++l) out.push_back({i, j, k, l});
  return out;
}

// Value, gradient and Hessian of sum_m c_m prod_{i in m} q_i, by differentiating each product.
Reference evaluate(const std::vector<double>& c, const Eigen::VectorXd& q) {
  const int r = static_cast<int>(q.size());
  const auto terms = monomials(r);
  EXPECT_EQ(terms.size(), c.size());
  Reference out{0, Eigen::VectorXd::Zero(r), Eigen::MatrixXd::Zero(r, r)};
  for (size_t m = 0; m < terms.size(); ++m) {
    const auto& idx = terms[m];
    auto productWithout = [&](int skipA, int skipB) {
      double p = 1;
      for (int s = 0; s < static_cast<int>(idx.size()); ++s)
        if (s != skipA && s != skipB) p *= q[idx[s]];
      return p;
    };
    out.energy += c[m] * productWithout(-1, -1);
    for (int a = 0; a < static_cast<int>(idx.size()); ++a) {
      out.gradient[idx[a]] += c[m] * productWithout(a, -1);
      for (int b = 0; b < static_cast<int>(idx.size()); ++b)
        if (b != a) out.hessian(idx[a], idx[b]) += c[m] * productWithout(a, b);
    }
  }
  return out;
}

struct Body {
  TetMesh mesh;
  std::vector<Material> perTet;
  Eigen::MatrixXd U;
  Partition partition;
};

Body makeBody(int r) {
  int size = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  Body s;
  s.mesh = makeBoxMesh({0.8, 0.3, 0.2}, {4, 2, 2});
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> jitter(-0.02, 0.02);
  for (auto& x : s.mesh.vertices) x += Eigen::Vector3d(jitter(rng), jitter(rng), jitter(rng));
  for (int t = 0; t < s.mesh.tetCount(); ++t) {
    Material m;
    m.youngsModulus = t % 2 ? 2e6 : 5e5;
    m.poissonRatio = t % 3 ? 0.45 : 0.2;
    s.perTet.push_back(m);
  }
  std::normal_distribution<double> n(0, 1);
  s.U.resize(3 * s.mesh.vertexCount(), r);
  for (Eigen::Index i = 0; i < s.U.size(); ++i) s.U.data()[i] = n(rng);
  s.partition = partitionMesh(s.mesh, {size});
  return s;
}

} // namespace

TEST(EnergyPolynomial, MatchesTheFullSpaceModelFromTinyToLargeDeformation) {
  const int r = 5;
  Body s = makeBody(r);
  EnergyPolynomial poly = computeEnergyPolynomial(MPI_COMM_WORLD, s.mesh, s.perTet, s.partition.tetPart, s.U, {});
  StVKForceModel model(s.mesh, s.perTet);
  std::mt19937 rng(9);
  std::normal_distribution<double> n(0, 1);
  double worstForce = 0, worstStiffness = 0, worstEnergy = 0;
  for (int trial = 0; trial < 20; ++trial) {
    // ||Uq|| from 1e-4 of the object's size up to its size (0.8): the cubic and quartic terms dominate there.
    Eigen::VectorXd q(r);
    for (auto& x : q) x = n(rng);
    q *= std::pow(10.0, -4.0 + 4.0 * trial / 19.0) * 0.8 / (s.U * q).cwiseAbs().maxCoeff();
    const Eigen::VectorXd u = s.U * q;
    Eigen::VectorXd f;
    model.internalForce(u, f);
    const Eigen::VectorXd force = s.U.transpose() * f;
    const Eigen::MatrixXd K = s.U.transpose() * model.tangentStiffness(u) * s.U;
    const Reference p = evaluate(poly.coefficients, q);
    worstEnergy = std::max(worstEnergy, std::abs(p.energy - model.energy(u)) / model.energy(u));
    worstForce = std::max(worstForce, (p.gradient - force).norm() / force.norm());
    worstStiffness = std::max(worstStiffness, (p.hessian - K).norm() / K.norm());
  }
  EXPECT_LT(worstEnergy, 1e-10);
  EXPECT_LT(worstForce, 1e-10);
  EXPECT_LT(worstStiffness, 1e-10);
  RecordProperty("worst_force_error", std::to_string(worstForce));
}

TEST(EnergyPolynomial, RestStiffnessIsTheProjectedLinearStiffness) {
  const int r = 4;
  Body s = makeBody(r);
  EnergyPolynomial poly = computeEnergyPolynomial(MPI_COMM_WORLD, s.mesh, s.perTet, s.partition.tetPart, s.U, {});
  StVKForceModel model(s.mesh, s.perTet);
  const Eigen::MatrixXd K0 = s.U.transpose() * model.tangentStiffness(Eigen::VectorXd::Zero(s.U.rows())) * s.U;
  const Reference p = evaluate(poly.coefficients, Eigen::VectorXd::Zero(r));
  EXPECT_LT((p.hessian - K0).norm(), 1e-12 * K0.norm());
  EXPECT_EQ(p.gradient.norm(), 0.0);
}

TEST(EnergyPolynomial, BlockSizeChangesOnlyRoundOff) {
  const int r = 6;
  Body s = makeBody(r);
  PolynomialSettings one, odd;
  one.tetsPerBlock = 1;
  odd.tetsPerBlock = 7;
  const auto a = computeEnergyPolynomial(MPI_COMM_WORLD, s.mesh, s.perTet, s.partition.tetPart, s.U, one).coefficients;
  const auto b = computeEnergyPolynomial(MPI_COMM_WORLD, s.mesh, s.perTet, s.partition.tetPart, s.U, odd).coefficients;
  const Eigen::Map<const Eigen::VectorXd> va(a.data(), a.size()), vb(b.data(), b.size());
  EXPECT_LT((va - vb).norm(), 1e-13 * va.norm());
  // And the ranks' partial sums add to the same polynomial as one rank computing everything.
  const std::vector<int> allMine(s.mesh.tetCount(), 0);
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm self = MPI_COMM_SELF;
  if (rank == 0) {
    const auto c = computeEnergyPolynomial(self, s.mesh, s.perTet, allMine, s.U, {}).coefficients;
    const Eigen::Map<const Eigen::VectorXd> vc(c.data(), c.size());
    EXPECT_LT((va - vc).norm(), 1e-12 * va.norm());
  }
}

// A rank's tets are summed in fixed slices, each in a Gram of its own, added in slice order: any
// number of threads gives the same bits, and the sum agrees with one Gram over all tets.
TEST(EnergyPolynomial, ThreadsChangeNoBit) {
  const int r = 6;
  Body s = makeBody(r);
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  const size_t mine = static_cast<size_t>(std::count(s.partition.tetPart.begin(), s.partition.tetPart.end(), rank));
  ASSERT_EQ(gramSlices(ReducedEnergyRows::columns(r), mine), 4) << "too few tets to slice: the test would test nothing";
  PolynomialSettings settings;
  settings.tetsPerBlock = 3;  // several blocks per slice
  std::vector<double> first;
  for (int threads : {1, 2, 3, 4, 9}) {
    settings.threads = threads;
    int64_t reported = 0;
    settings.progress = [&](int64_t done, int64_t total) {
      EXPECT_GE(done, reported);
      EXPECT_EQ(total, static_cast<int64_t>(mine));
      reported = done;
    };
    const auto c = computeEnergyPolynomial(MPI_COMM_WORLD, s.mesh, s.perTet, s.partition.tetPart, s.U, settings).coefficients;
    EXPECT_EQ(reported, static_cast<int64_t>(mine)) << threads << " threads: progress did not reach every tet";
    if (first.empty())
      first = c;
    else
      EXPECT_EQ(std::memcmp(c.data(), first.data(), sizeof(double) * c.size()), 0) << threads << " threads";
  }
  const Eigen::MatrixXd gram = reducedEnergyGram(s.mesh, s.perTet, s.U);
  const std::vector<double> whole = energyCoefficientsFromGram(gram.data(), static_cast<int>(gram.rows()), r);
  const Eigen::Map<const Eigen::VectorXd> vf(first.data(), first.size()), vw(whole.data(), whole.size());
  EXPECT_LT((vf - vw).norm(), 1e-12 * vw.norm());
}
