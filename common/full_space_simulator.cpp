#include "common/full_space_simulator.h"

#include <stdexcept>

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseLU>

#include "common/mass_matrix.h"
#include "common/modal_rotation.h"
#include "quiver/modal_warping.h"

namespace quiver {

using SparseMatrix = Eigen::SparseMatrix<double>;

// Conjugate gradients with an incomplete Cholesky preconditioner: elasticity is badly conditioned
// (stiff, thin parts), where plain Jacobi needs many times more iterations.
struct FullSpaceSimulator::Solvers {
  Eigen::SimplicialLLT<SparseMatrix> llt;
  Eigen::SimplicialLDLT<SparseMatrix> ldlt;
  Eigen::ConjugateGradient<SparseMatrix, Eigen::Lower | Eigen::Upper, Eigen::IncompleteCholesky<double>> cg;
  Eigen::SparseLU<SparseMatrix> lu;
};

SparseSolver parseSparseSolver(const std::string& name) {
  if (name == "llt") return SparseSolver::LLT;
  if (name == "ldlt") return SparseSolver::LDLT;
  if (name == "cg") return SparseSolver::CG;
  if (name == "lu") return SparseSolver::LU;
  throw std::invalid_argument("unknown solver '" + name + "' (llt, ldlt, cg or lu)");
}

FullSpaceSimulator::FullSpaceSimulator(const TetMesh& mesh, const std::vector<Material>& perTet,
                                       const std::vector<int>& fixedVertices, const FullSpaceSettings& settings)
    : model_(mesh, perTet), settings_(settings), rest_(mesh.vertices), mesh_(mesh),
      solvers_(std::make_unique<Solvers>()) {
  if (!(settings.timeStep > 0) || settings.maxNewtonIterations < 1)
    throw std::invalid_argument("full-space simulator: time step must be > 0 and Newton iterations >= 1");
  const int n = model_.dofCount();
  u_ = v_ = a_ = stepForce_ = gravityForce_ = Eigen::VectorXd::Zero(n);
  tangent_ = model_.tangentStiffness(u_);
  restStiffness_ = tangent_;
  // The mass pattern lies inside the tangent's (both couple vertices sharing a tet): adding a zero
  // tangent puts M on the same pattern, so the system is a sum of value arrays.
  mass_ = consistentMassMatrix(mesh, perTet) + 0.0 * tangent_;
  if (mass_.nonZeros() != tangent_.nonZeros()) throw std::logic_error("full-space simulator: mass and tangent patterns differ");
  system_ = tangent_;
  fixedDof_.assign(n, 0);
  for (int v : fixedVertices)
    for (int c = 0; c < 3; ++c) fixedDof_[3 * v + c] = 1;
  diagonalSlot_.assign(n, -1);
  for (int col = 0; col < n; ++col)
    for (SparseMatrix::InnerIterator it(system_, col); it; ++it) {
      const int slot = static_cast<int>(&it.valueRef() - system_.valuePtr());
      if (it.row() == col) diagonalSlot_[col] = slot;
      if (fixedDof_[it.row()] || fixedDof_[col]) constrainedSlots_.push_back(slot);
    }
}

FullSpaceSimulator::~FullSpaceSimulator() = default;

void FullSpaceSimulator::addVertexForce(int vertex, const Eigen::Vector3d& force) {
  if (vertex < 0 || 3 * vertex >= dofCount()) throw std::invalid_argument("addVertexForce: no such vertex");
  Eigen::Vector3d local = force;
  if (settings_.elasticity == QV_ELASTICITY_MODAL_WARPING) {  // into the vertex's rotated frame
    const Eigen::Vector3d back = -vertexRotations(mesh_, u_).middleRows(3 * vertex, 3);
    warping::rotate(back.data(), force.data(), local.data());
  }
  stepForce_.segment<3>(3 * vertex) += local;
}

Eigen::VectorXd FullSpaceSimulator::displacement() const {
  if (settings_.elasticity != QV_ELASTICITY_MODAL_WARPING) return u_;
  const Eigen::MatrixXd w = vertexRotations(mesh_, u_);
  Eigen::VectorXd out(u_.size());
  for (int v = 0; 3 * v < dofCount(); ++v)
    warping::warpDisplacement(w.col(0).data() + 3 * v, u_.data() + 3 * v, out.data() + 3 * v);
  return out;
}

double FullSpaceSimulator::elasticEnergy() const {
  return settings_.elasticity == QV_ELASTICITY_STVK ? model_.energy(u_) : 0.5 * u_.dot(restStiffness_ * u_);
}

void FullSpaceSimulator::setGravity(const Eigen::Vector3d& g) {
  Eigen::VectorXd field(dofCount());
  for (int i = 0; i < dofCount(); ++i) field[i] = g[i % 3];
  gravityForce_ = mass_ * field;
}

void FullSpaceSimulator::setSprings(const std::vector<int>& vertices, const std::vector<Eigen::Vector3d>& targets,
                                   double stiffness) {
  if (vertices.size() != targets.size() || !(stiffness > 0))
    throw std::invalid_argument("setSprings: one target per vertex and a positive stiffness");
  springVertices_ = vertices;
  springTargets_ = targets;
  springStiffness_ = stiffness;
}

void FullSpaceSimulator::clearSprings() {
  springVertices_.clear();
  springTargets_.clear();
}

double FullSpaceSimulator::kineticEnergy() const { return 0.5 * v_.dot(mass_ * v_); }

void FullSpaceSimulator::applyConstraints(SparseMatrix& A, Eigen::VectorXd& b) const {
  double* values = A.valuePtr();
  for (int slot : constrainedSlots_) values[slot] = 0;
  for (int d = 0; d < dofCount(); ++d)
    if (fixedDof_[d]) {
      values[diagonalSlot_[d]] = 1;
      b[d] = 0;
    }
}

void FullSpaceSimulator::solve(const SparseMatrix& A, const Eigen::VectorXd& b, Eigen::VectorXd& x) {
  Solvers& s = *solvers_;
  bool ok = true;
  switch (settings_.solver) {
    case SparseSolver::LLT:
      if (!analyzed_) s.llt.analyzePattern(A);
      s.llt.factorize(A);
      ok = s.llt.info() == Eigen::Success;
      if (ok) x = s.llt.solve(b);
      break;
    case SparseSolver::LDLT:
      if (!analyzed_) s.ldlt.analyzePattern(A);
      s.ldlt.factorize(A);
      ok = s.ldlt.info() == Eigen::Success;
      if (ok) x = s.ldlt.solve(b);
      break;
    case SparseSolver::LU:
      if (!analyzed_) s.lu.analyzePattern(A);
      s.lu.factorize(A);
      ok = s.lu.info() == Eigen::Success;
      if (ok) x = s.lu.solve(b);
      break;
    case SparseSolver::CG:
      s.cg.setTolerance(settings_.cgTolerance);
      s.cg.compute(A);
      x = s.cg.solve(b);
      ok = s.cg.info() == Eigen::Success;
      break;
  }
  analyzed_ = true;
  if (!ok) throw std::runtime_error("full-space simulator: the linear solver failed (indefinite tangent for llt?)");
}

int FullSpaceSimulator::step() {
  const int iterations = advance(settings_.timeStep, 0);
  stepForce_.setZero();
  return iterations;
}

int FullSpaceSimulator::advance(double h, int depth) {
  constexpr int kMaxHalvings = 6;
  const Eigen::VectorXd u = u_, v = v_, a = a_;
  try {
    return newmarkStep(h);
  } catch (const NewtonFailure&) {
    // Sudden changes (a released spring, a twist) can defeat Newton from the last acceleration:
    // take the step as two halves instead, down to 1/64 of it.
    if (depth >= kMaxHalvings) throw;
    u_ = u;
    v_ = v;
    a_ = a;
    return advance(h / 2, depth + 1) + advance(h / 2, depth + 1);
  }
}

int FullSpaceSimulator::newmarkStep(double h) {
  const double beta = 0.25, gamma = 0.5;
  const double alpha = settings_.rayleighAlpha, betaK = settings_.rayleighBeta;
  const Eigen::VectorXd external = stepForce_ + gravityForce_;
  Eigen::VectorXd next = a_, q, vel, residual, delta, trialResidual;
  // The Newmark residual at acceleration `acc`: M acc + C(q) vel + R(q) - f, with q and vel from acc.
  // Leaves q, vel and the elastic tangent at q (when asked) in the members used below.
  auto residualAt = [&](const Eigen::VectorXd& acc, Eigen::VectorXd& out, bool withTangent) {
    q = u_ + h * v_ + h * h * ((0.5 - beta) * a_ + beta * acc);
    vel = v_ + h * ((1 - gamma) * a_ + gamma * acc);
    if (settings_.elasticity == QV_ELASTICITY_STVK) {
      model_.internalForce(q, force_);
      if (withTangent) model_.tangentStiffness(q, tangent_);
    } else {
      force_ = restStiffness_ * q;  // tangent_ stays K(0)
    }
    for (size_t k = 0; k < springVertices_.size(); ++k) {
      const int v = springVertices_[k];
      force_.segment<3>(3 * v) += springStiffness_ * (rest_[v] + q.segment<3>(3 * v) - springTargets_[k]);
    }
    out = mass_ * acc + alpha * (mass_ * vel) + betaK * (tangent_ * vel) + force_ - external;
    for (int d = 0; d < dofCount(); ++d)
      if (fixedDof_[d]) out[d] = 0;
    return (mass_ * acc).norm() + external.norm() + force_.norm() + 1e-300;
  };
  for (int it = 0; it <= settings_.maxNewtonIterations; ++it) {
    const double scale = residualAt(next, residual, true);
    if (residual.norm() <= settings_.newtonTolerance * scale && it > 0) {
      u_ = q;
      v_ = vel;
      a_ = next;
      return it;
    }
    if (it == settings_.maxNewtonIterations) break;
    // J = (1 + gamma h alpha) M + (gamma h beta_K + beta h^2) K, springs on the diagonal.
    const double cm = 1 + gamma * h * alpha, ck = gamma * h * betaK + beta * h * h;
    double* A = system_.valuePtr();
    const double* M = mass_.valuePtr();
    const double* K = tangent_.valuePtr();
    for (Eigen::Index k = 0; k < system_.nonZeros(); ++k) A[k] = cm * M[k] + ck * K[k];
    for (int v : springVertices_)
      for (int c = 0; c < 3; ++c) A[diagonalSlot_[3 * v + c]] += beta * h * h * springStiffness_;
    Eigen::VectorXd rhs = -residual;
    applyConstraints(system_, rhs);
    solve(system_, rhs, delta);
    // Backtracking: after a sudden release the last acceleration is a poor start, and a full
    // Newton step on StVK can overshoot; halve it until the residual drops.
    double step = 1;
    for (int halving = 0; halving < 8; ++halving, step *= 0.5) {
      residualAt(next + step * delta, trialResidual, false);
      if (trialResidual.norm() < residual.norm()) break;
    }
    next += step * delta;
  }
  throw NewtonFailure("full-space simulator: Newton did not converge in " +
                      std::to_string(settings_.maxNewtonIterations) + " iterations, even on 1/64 of the time step");
}

} // namespace quiver
