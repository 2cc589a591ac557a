#include "common/static_equilibrium.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/Cholesky>
#include <Eigen/SparseCholesky>

namespace quiver {

namespace {

// Phi, its gradient and the spring terms at u, for load fraction `s`.
struct Energy {
  const StVKForceModel& model;
  const std::vector<Eigen::Vector3d>& rest;
  const StaticLoad& load;
  double s = 1;

  double value(const Eigen::VectorXd& u) const {
    double phi = model.energy(u) - s * load.force.dot(u);
    for (size_t k = 0; k < load.springVertices.size(); ++k) {
      const int v = load.springVertices[k];
      phi += 0.5 * load.springStiffness * (u.segment<3>(3 * v) - s * (load.springTargets[k] - rest[v])).squaredNorm();
    }
    return phi;
  }
  // Gradient into g; returns the force scale of the convergence test.
  double gradient(const Eigen::VectorXd& u, Eigen::VectorXd& g) const {
    model.internalForce(u, g);
    double scale = g.norm() + s * load.force.norm();
    g -= s * load.force;
    for (size_t k = 0; k < load.springVertices.size(); ++k) {
      const int v = load.springVertices[k];
      const Eigen::Vector3d pull = load.springStiffness * (u.segment<3>(3 * v) - s * (load.springTargets[k] - rest[v]));
      g.segment<3>(3 * v) += pull;
      scale += pull.norm();
    }
    return scale;
  }
  Eigen::SparseMatrix<double> hessian(const Eigen::VectorXd& u) const {
    Eigen::SparseMatrix<double> H = model.tangentStiffness(u);
    for (int v : load.springVertices)
      for (int c = 0; c < 3; ++c) H.coeffRef(3 * v + c, 3 * v + c) += load.springStiffness;
    return H;
  }
};

// Newton with backtracking from x over the increments. `toU` maps the unknowns to u, `pull` a
// full gradient back to the unknowns, `direction` solves (H + mu I) d = -g for a given shift.
template <class ToU, class Pull, class Direction>
Eigen::VectorXd minimize(Energy& energy, Eigen::VectorXd x, ToU toU, Pull pull, Direction direction,
                         const StaticSettings& settings) {
  Eigen::VectorXd full;
  for (int step = 1; step <= settings.increments; ++step) {
    energy.s = static_cast<double>(step) / settings.increments;
    bool converged = false;
    for (int it = 0; it < settings.maxIterations && !converged; ++it) {
      const Eigen::VectorXd u = toU(x);
      const double scale = energy.gradient(u, full);
      const Eigen::VectorXd g = pull(full);
      if (g.norm() <= settings.tolerance * scale) {
        converged = true;
        break;
      }
      const Eigen::VectorXd d = direction(u, g);
      const double phi = energy.value(u), slope = g.dot(d);
      double length = 1;
      for (int cut = 0; cut < 40 && energy.value(toU(x + length * d)) > phi + 1e-4 * length * slope; ++cut) length /= 2;
      x += length * d;
    }
    if (!converged) {
      const double scale = energy.gradient(toU(x), full);
      if (!(pull(full).norm() <= settings.accepted * scale))
        throw std::runtime_error("static equilibrium: load increment " + std::to_string(step) + " of " +
                                 std::to_string(settings.increments) + " did not converge (relative gradient " +
                                 std::to_string(pull(full).norm() / scale) + ")");
    }
  }
  return toU(x);
}

} // namespace

Eigen::VectorXd solveStatic(const StVKForceModel& model, const std::vector<Eigen::Vector3d>& rest,
                            const std::vector<int>& fixed, const StaticLoad& load, const StaticSettings& settings,
                            const SymmetricSolve& solve) {
  const int n = model.dofCount();
  std::vector<char> isFixed(n, 0);
  for (int v : fixed)
    for (int c = 0; c < 3; ++c) isFixed[3 * v + c] = 1;
  std::vector<int> freeDof;
  for (int i = 0; i < n; ++i)
    if (!isFixed[i]) freeDof.push_back(i);
  const auto toU = [&](const Eigen::VectorXd& x) {
    Eigen::VectorXd u = Eigen::VectorXd::Zero(n);
    for (size_t i = 0; i < freeDof.size(); ++i) u[freeDof[i]] = x[i];
    return u;
  };
  const auto pull = [&](const Eigen::VectorXd& g) {
    Eigen::VectorXd out(freeDof.size());
    for (size_t i = 0; i < freeDof.size(); ++i) out[i] = g[freeDof[i]];
    return out;
  };
  Energy energy{model, rest, load};
  // The Hessian's pattern never changes (K's, the springs' diagonal): order it once.
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt;
  bool analyzed = false;
  const SymmetricSolve simplicial = [&](const Eigen::SparseMatrix<double>& H, const Eigen::VectorXd& b,
                                        Eigen::VectorXd& x) {
    if (!analyzed) {
      ldlt.analyzePattern(H);
      analyzed = true;
    }
    ldlt.factorize(H);
    if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 0)) return false;
    x = ldlt.solve(b);
    return true;
  };
  const SymmetricSolve& solver = solve ? solve : simplicial;
  const auto direction = [&](const Eigen::VectorXd& u, const Eigen::VectorXd& g) {
    Eigen::SparseMatrix<double> H = energy.hessian(u);
    std::vector<int> index(n, -1);
    for (size_t i = 0; i < freeDof.size(); ++i) index[freeDof[i]] = static_cast<int>(i);
    std::vector<Eigen::Triplet<double>> entries;
    double largest = 0;
    for (int col = 0; col < H.outerSize(); ++col)
      for (Eigen::SparseMatrix<double>::InnerIterator it(H, col); it; ++it)
        if (index[it.row()] >= 0 && index[it.col()] >= 0) {
          entries.emplace_back(index[it.row()], index[it.col()], it.value());
          if (it.row() == it.col()) largest = std::max(largest, std::abs(it.value()));
        }
    Eigen::SparseMatrix<double> Hf(static_cast<Eigen::Index>(freeDof.size()), static_cast<Eigen::Index>(freeDof.size()));
    Hf.setFromTriplets(entries.begin(), entries.end());
    Eigen::SparseMatrix<double> I(Hf.rows(), Hf.cols());
    I.setIdentity();
    Eigen::VectorXd d;
    for (double mu = 0;; mu = mu > 0 ? 10 * mu : 1e-8 * largest) {
      if (solver(Hf + mu * I, -g, d)) return d;
      if (mu > 1e6 * largest) throw std::runtime_error("static equilibrium: the Hessian cannot be made positive definite");
    }
  };
  return minimize(energy, Eigen::VectorXd::Zero(static_cast<Eigen::Index>(freeDof.size())), toU, pull, direction,
                  settings);
}

Eigen::VectorXd solveStaticReduced(const StVKForceModel& model, const std::vector<Eigen::Vector3d>& rest,
                                   const Eigen::MatrixXd& U, const StaticLoad& load, const StaticSettings& settings) {
  Energy energy{model, rest, load};
  const auto toU = [&](const Eigen::VectorXd& q) { return Eigen::VectorXd(U * q); };
  const auto pull = [&](const Eigen::VectorXd& g) { return Eigen::VectorXd(U.transpose() * g); };
  const auto direction = [&](const Eigen::VectorXd& u, const Eigen::VectorXd& g) {
    const Eigen::MatrixXd H = U.transpose() * (energy.hessian(u) * U);
    const double largest = H.diagonal().cwiseAbs().maxCoeff();
    for (double mu = 0;; mu = mu > 0 ? 10 * mu : 1e-8 * largest) {
      Eigen::LLT<Eigen::MatrixXd> llt(H + mu * Eigen::MatrixXd::Identity(H.rows(), H.cols()));
      if (llt.info() == Eigen::Success) return Eigen::VectorXd(llt.solve(-g));
      if (mu > 1e6 * largest) throw std::runtime_error("static equilibrium: the reduced Hessian cannot be made positive definite");
    }
  };
  return minimize(energy, Eigen::VectorXd::Zero(U.cols()), toU, pull, direction, settings);
}

} // namespace quiver
