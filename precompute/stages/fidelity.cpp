#include "precompute/stages/fidelity.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <functional>
#include <memory>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include "common/mass_matrix.h"
#include "common/static_equilibrium.h"
#include "precompute/checkpoint.h"
#include "precompute/sequential_cholesky.h"
#include "quiver/quiver.h"

namespace quiver {

namespace {

// The load cases, in the order loadCases builds them.
const char* const kCases[] = {"own weight", "pull", "twist 30", "twist 60"};

Eigen::Vector3d centroid(const TetMesh& mesh, const std::vector<int>& vertices) {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (int v : vertices) c += mesh.vertices[v];
  return c / static_cast<double>(vertices.size());
}

// The far part and the loads on it; springs stiff against the object (10 E h per vertex).
std::vector<std::pair<std::string, StaticLoad>> loadCases(const MeshInputs& in) {
  const TetMesh& m = in.mesh.mesh;
  const int n = 3 * m.vertexCount();
  const auto box = boundingBox(m);
  const double size = (box[1] - box[0]).norm();
  const Eigen::Vector3d fixedCentre = centroid(m, in.fixed);
  double farthest = 0;
  for (const auto& x : m.vertices) farthest = std::max(farthest, (x - fixedCentre).norm());
  std::vector<int> far;
  for (int v = 0; v < m.vertexCount(); ++v)
    if ((m.vertices[v] - fixedCentre).norm() >= 0.9 * farthest) far.push_back(v);
  const Eigen::Vector3d farCentre = centroid(m, far), axis = (farCentre - fixedCentre).normalized();
  Eigen::Index least = 0;
  axis.cwiseAbs().minCoeff(&least);
  const Eigen::Vector3d sideways = (Eigen::Vector3d::Unit(least) - Eigen::Vector3d::Unit(least).dot(axis) * axis).normalized();
  double E = 0, volume = 0;
  for (int t = 0; t < m.tetCount(); ++t) {
    const double V = std::abs(signedVolume6(m, t)) / 6;
    E += V * in.perTet[t].youngsModulus;
    volume += V;
  }
  const double stiffness = 10 * (E / volume) * std::cbrt(volume / m.tetCount());

  std::vector<std::pair<std::string, StaticLoad>> cases;
  StaticLoad weight;
  Eigen::VectorXd down = Eigen::VectorXd::Zero(n);
  for (int v = 0; v < m.vertexCount(); ++v) down[3 * v + 2] = -QV_STANDARD_GRAVITY;
  weight.force = consistentMassMatrix(m, in.perTet) * down;
  cases.emplace_back(kCases[0], weight);
  const auto springs = [&](const std::function<Eigen::Vector3d(const Eigen::Vector3d&)>& move) {
    StaticLoad load;
    load.force = Eigen::VectorXd::Zero(n);
    load.springStiffness = stiffness;
    for (int v : far) {
      load.springVertices.push_back(v);
      load.springTargets.push_back(move(m.vertices[v]));
    }
    return load;
  };
  cases.emplace_back(kCases[1], springs([&](const Eigen::Vector3d& x) { return Eigen::Vector3d(x + 0.1 * size * sideways); }));
  for (int degrees : {30, 60}) {
    const Eigen::Matrix3d R = Eigen::AngleAxisd(degrees * M_PI / 180, axis).toRotationMatrix();
    cases.emplace_back(kCases[degrees == 30 ? 2 : 3],
                       springs([&](const Eigen::Vector3d& x) { return Eigen::Vector3d(farCentre + R * (x - farCentre)); }));
  }
  return cases;
}

// A MUMPS failure other than an indefinite matrix (memory, workspace): the bake stops with it
// rather than reporting the load case as one without an equilibrium.
struct SolverFailure : std::exception {
  explicit SolverFailure(std::string text) : message(std::move(text)) {}
  const char* what() const noexcept override { return message.c_str(); }
  std::string message;
};

// The full-space Newton systems through MUMPS in a METIS order (sequential_cholesky.h), ordered and
// analysed once per equilibrium (the Hessian's pattern never changes; checked), then factored anew
// with each Hessian's values. On the 12.8k-tet bridge Eigen's simplicial LDLT took most of this
// stage's 12 s (165 factorisations), and MUMPS ordering and analysing each one anew was no faster.
class MumpsSolve {
public:
  bool operator()(const Eigen::SparseMatrix<double>& H, const Eigen::VectorXd& b, Eigen::VectorXd& x) {
    SequentialCholesky::UpperTriangle upper;
    upper.n = static_cast<PetscInt>(H.rows());
    const size_t entries = static_cast<size_t>(H.nonZeros() + H.rows()) / 2;
    upper.rows.reserve(entries);
    upper.cols.reserve(entries);
    upper.values.reserve(entries);
    for (int col = 0; col < H.outerSize(); ++col)
      for (Eigen::SparseMatrix<double>::InnerIterator it(H, col); it; ++it)
        if (it.row() <= col) {
          upper.rows.push_back(static_cast<int>(it.row()));
          upper.cols.push_back(col);
          upper.values.push_back(it.value());
        }
    try {
      if (factor_ && upper.rows == rows_ && upper.cols == cols_) {
        factor_->refactor(upper.values);
      } else {
        factor_.reset();
        rows_ = upper.rows;
        cols_ = upper.cols;
        factor_ = std::make_unique<SequentialCholesky>(std::move(upper), 0, true);
      }
    } catch (const NotPositiveDefinite&) {
      return false;
    } catch (const std::runtime_error& e) {
      throw SolverFailure(std::string("fidelity: ") + e.what());
    }
    x = b;
    factor_->solveInPlace(x.data(), 1);
    return true;
  }

private:
  std::unique_ptr<SequentialCholesky> factor_;
  std::vector<int> rows_, cols_;  // the pattern factor_ was ordered and analysed for
};

FidelityReport measure(const MeshInputs& in, const Eigen::MatrixXd& U, const LinearModes& modes) {
  const TetMesh& m = in.mesh.mesh;
  const StVKForceModel model(m, in.perTet);
  // Percent-level answers: four load increments and a gradient of 1e-7 are plenty.
  StaticSettings settings;
  settings.increments = 4;
  settings.tolerance = 1e-7;
  settings.accepted = 1e-5;
  FidelityReport report;
  const auto box = boundingBox(m);
  const double size = (box[1] - box[0]).norm();
  if (!in.freeObject())
    for (const auto& [name, load] : loadCases(in)) {
      // A load this mesh cannot carry to an equilibrium (a slender object under its own weight
      // folds) is reported as not measured (NaN): the report never fails the bake.
      FidelityCase measured{name, std::nan(""), std::nan("")};
      try {
        Eigen::VectorXd full;
        {  // the factor is freed before the reduced solve
          MumpsSolve mumps;
          full = solveStatic(model, m.vertices, in.fixed, load, settings,
                             [&mumps](const Eigen::SparseMatrix<double>& H, const Eigen::VectorXd& b, Eigen::VectorXd& x) {
                               return mumps(H, b, x);
                             });
        }
        const Eigen::VectorXd reduced = solveStaticReduced(model, m.vertices, U, load, settings);
        double largest = 0;
        for (int v = 0; v < m.vertexCount(); ++v) largest = std::max(largest, full.segment<3>(3 * v).norm());
        measured.error = (reduced - full).norm() / full.norm();
        measured.largestDisplacement = largest / size;
      } catch (const std::runtime_error&) {
      }
      report.cases.push_back(measured);
    }
  // Reduced frequencies: U^T K(0) U (U is M-orthonormal), sorted, against the baked ones in order.
  const Eigen::MatrixXd reducedStiffness = U.transpose() * (model.tangentStiffness(Eigen::VectorXd::Zero(U.rows())) * U);
  const Eigen::VectorXd lambda = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(reducedStiffness).eigenvalues();
  // Rigid motions in a (user's) basis of a free object show as eigenvalues near zero: not modes.
  Eigen::Index first = 0;
  while (first < lambda.size() && lambda[first] < 1e-6 * modes.eigenvalues[0]) ++first;
  for (size_t i = 0; i < modes.eigenvalues.size() && first + static_cast<Eigen::Index>(i) < lambda.size(); ++i)
    report.frequencyErrors.push_back(std::sqrt(std::max(lambda[first + i], 0.0) / modes.eigenvalues[i]) - 1);
  return report;
}

std::string percent(double x) { return shortNumber(100 * x) + "%"; }

} // namespace

FidelityReport fidelityStage(StageRunner& stages, const BakeContext& ctx, const MeshInputs& in,
                             const Eigen::MatrixXd& basis, const LinearModes& modes, Archive& archive) {
  FidelityReport report = stages.run("fidelity", [&] {
    FidelityReport measured;
    ctx.onRankZero([&] { measured = measure(in, basis, modes); });
    // Every rank writes the archive's datasets collectively: give them rank 0's numbers.
    std::vector<double> numbers;
    for (const FidelityCase& c : measured.cases) numbers.insert(numbers.end(), {c.error, c.largestDisplacement});
    numbers.insert(numbers.end(), measured.frequencyErrors.begin(), measured.frequencyErrors.end());
    int counts[2] = {static_cast<int>(measured.cases.size()), static_cast<int>(measured.frequencyErrors.size())};
    MPI_Bcast(counts, 2, MPI_INT, 0, ctx.comm());
    numbers.resize(2 * counts[0] + counts[1]);
    MPI_Bcast(numbers.data(), static_cast<int>(numbers.size()), MPI_DOUBLE, 0, ctx.comm());
    FidelityReport shared;
    for (int i = 0; i < counts[0]; ++i) shared.cases.push_back({kCases[i], numbers[2 * i], numbers[2 * i + 1]});
    shared.frequencyErrors.assign(numbers.begin() + 2 * counts[0], numbers.end());
    return shared;
  });
  resetGroup(archive, "/fidelity");
  std::string names;
  std::vector<double> errors, displacements;
  for (const FidelityCase& c : report.cases) {
    names += (names.empty() ? "" : ",") + c.name;
    errors.push_back(c.error);
    displacements.push_back(c.largestDisplacement);
  }
  archive.setAttribute("/fidelity", "cases", names);
  writeVector(archive, "/fidelity/displacement_error", errors);
  writeVector(archive, "/fidelity/largest_displacement", displacements);
  writeVector(archive, "/fidelity/frequency_error", report.frequencyErrors);
  archive.flush();

  std::string line;
  for (const FidelityCase& c : report.cases)
    line += c.name + (std::isnan(c.error) ? std::string(" not measured (no static equilibrium found), ")
                                          : " " + percent(c.error) + " off (at " + percent(c.largestDisplacement) +
                                                " of the size), ");
  double worst = 0;
  int close = 0;
  for (double e : report.frequencyErrors) {
    worst = std::max(worst, std::abs(e));
    close += std::abs(e) <= 0.01;
  }
  line += std::to_string(close) + " of the " + std::to_string(report.frequencyErrors.size()) +
          " baked frequencies within 1% (worst " + percent(worst) + " off)";
  stages.report(line);
  return report;
}

} // namespace quiver
