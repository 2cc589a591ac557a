#include "precompute/sequential_cholesky.h"

#include <algorithm>
#include <climits>
#include <stdexcept>
#include <string>

#include <dmumps_c.h>
#include <metis.h>
#include <mpi.h>

#include "precompute/petsc_handle.h"

namespace quiver {

namespace {

constexpr MUMPS_INT kInit = -1, kEnd = -2, kAnalyse = 1, kFactor = 2, kSolve = 3;

// MUMPS's 1-based ICNTL/CNTL/INFOG numbering, as its manual and PETSc's option names use it.
MUMPS_INT& icntl(DMUMPS_STRUC_C& id, int i) { return id.icntl[i - 1]; }

std::string mumpsError(const DMUMPS_STRUC_C& id, const char* phase) {
  const MUMPS_INT code = id.infog[0], detail = id.infog[1];
  std::string what = "MUMPS " + std::string(phase) + " failed (INFOG(1) = " + std::to_string(code) +
                     ", INFOG(2) = " + std::to_string(detail) + ")";
  switch (code) {
  case -8: case -9: case -14: case -15: case -17: case -20:
    return what + ": its workspace was too small; raise -factor_mat_mumps_icntl_14 (the percentage it adds, now " +
           std::to_string(id.icntl[13]) + ")";
  case -10:
    return what + ": the matrix is numerically singular (are enough vertices fixed?)";
  case -13:
    return what + ": out of memory allocating " + std::to_string(detail < 0 ? -static_cast<long long>(detail) * 1000000LL
                                                                            : static_cast<long long>(detail)) + " entries";
  default:
    return what + "; see the MUMPS users' guide, section \"Error diagnostics\"";
  }
}

// Position of each of the first `ordered` variables in a nested-dissection elimination order of
// the graph whose nodes are blocks of `block` consecutive variables (a vertex's three), 1-based as
// MUMPS's PERM_IN wants it; the rest (Schur variables) follow in their own order. METIS's own
// random choices use a fixed seed: the same order every run.
std::vector<MUMPS_INT> nestedDissection(const SequentialCholesky::UpperTriangle& upper, PetscInt ordered, PetscInt block) {
  const PetscInt nodes = ordered / block;
  std::vector<std::vector<idx_t>> neighbours(static_cast<size_t>(nodes));
  for (size_t e = 0; e < upper.rows.size(); ++e) {
    if (upper.cols[e] >= ordered) continue;  // rows[e] <= cols[e]
    const idx_t a = upper.rows[e] / block, b = upper.cols[e] / block;
    if (a == b) continue;
    neighbours[a].push_back(b);
    neighbours[b].push_back(a);
  }
  std::vector<idx_t> offsets(static_cast<size_t>(nodes) + 1, 0), adjacency;
  for (PetscInt v = 0; v < nodes; ++v) {
    auto& list = neighbours[v];
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
    adjacency.insert(adjacency.end(), list.begin(), list.end());
    offsets[v + 1] = static_cast<idx_t>(adjacency.size());
    std::vector<idx_t>().swap(list);
  }
  std::vector<MUMPS_INT> perm(static_cast<size_t>(upper.n));
  for (PetscInt i = 0; i < upper.n; ++i) perm[i] = static_cast<MUMPS_INT>(i + 1);
  if (!adjacency.empty()) {  // METIS reads its adjacency even for a graph without edges
    idx_t count = static_cast<idx_t>(nodes);
    idx_t options[METIS_NOPTIONS];
    METIS_SetDefaultOptions(options);
    options[METIS_OPTION_NUMBERING] = 0;
    std::vector<idx_t> order(static_cast<size_t>(nodes)), position(static_cast<size_t>(nodes));
    if (METIS_NodeND(&count, offsets.data(), adjacency.data(), nullptr, options, order.data(), position.data()) != METIS_OK)
      throw std::runtime_error("METIS_NodeND failed to order a graph of " + std::to_string(nodes) + " vertices");
    for (PetscInt i = 0; i < ordered; ++i)
      perm[i] = static_cast<MUMPS_INT>(block * position[i / block] + i % block + 1);
  }
  return perm;
}

} // namespace

static_assert(sizeof(MUMPS_INT) == sizeof(int), "MUMPS built with 64-bit integers");

struct SequentialCholesky::Mumps {
  DMUMPS_STRUC_C id{};
  UpperTriangle upper;                     // 1-based once given to MUMPS
  std::vector<MUMPS_INT> perm, schurList;  // the elimination order; the Schur variables (1-based)
  Eigen::MatrixXd schur;                   // MUMPS writes the Schur complement here
  bool initialised = false;
  ~Mumps() {
    if (!initialised) return;
    id.job = kEnd;
    dmumps_c(&id);
  }
};

SequentialCholesky::UpperTriangle SequentialCholesky::upperTriangle(Mat A) {
  PetscInt n = 0, columns = 0, start = 0, end = 0;
  QV_PETSC(MatGetSize(A, &n, &columns));
  QV_PETSC(MatGetOwnershipRange(A, &start, &end));
  if (start != 0 || end != n || n != columns)
    throw std::logic_error("SequentialCholesky: the matrix must be square and held whole on this rank");
  UpperTriangle upper;
  upper.n = n;
  for (PetscInt i = 0; i < n; ++i) {
    PetscInt length = 0;
    const PetscInt* cols = nullptr;
    const PetscScalar* values = nullptr;
    QV_PETSC(MatGetRow(A, i, &length, &cols, &values));
    for (PetscInt e = 0; e < length; ++e)
      if (cols[e] >= i) {
        upper.rows.push_back(static_cast<int>(i));
        upper.cols.push_back(static_cast<int>(cols[e]));
        upper.values.push_back(values[e]);
      }
    QV_PETSC(MatRestoreRow(A, i, &length, &cols, &values));
  }
  return upper;
}

SequentialCholesky::SequentialCholesky(UpperTriangle upper, PetscInt schurSize, bool refactorable)
    : mumps_(std::make_unique<Mumps>()), rows_(upper.n), schurSize_(schurSize), refactorable_(refactorable) {
  const PetscInt n = upper.n;
  if (n > INT_MAX) throw std::runtime_error("SequentialCholesky: " + std::to_string(n) + " rows exceed MUMPS's int");
  if (schurSize < 0 || schurSize >= n)
    throw std::logic_error("SequentialCholesky: " + std::to_string(schurSize) + " Schur variables of " +
                           std::to_string(n) + " leave nothing to factor");
  Mumps& m = *mumps_;
  m.upper = std::move(upper);

  DMUMPS_STRUC_C& id = m.id;
  id.job = kInit;
  id.par = 1;  // this process factors
  id.sym = 1;  // positive definite: no pivoting; negative pivots are counted (INFOG(12))
  id.comm_fortran = static_cast<MUMPS_INT>(MPI_Comm_c2f(MPI_COMM_SELF));
  dmumps_c(&id);
  if (id.infog[0] < 0) throw std::runtime_error(mumpsError(id, "initialisation"));
  m.initialised = true;
  icntl(id, 1) = 6;  // errors, diagnostics and statistics to stdout, at the level ICNTL(4) sets
  icntl(id, 2) = 0;
  icntl(id, 3) = 6;
  icntl(id, 4) = 0;  // silent unless -factor_mat_mumps_icntl_4 asks
  icntl(id, 7) = 1;  // our order (perm_in)
  for (int i = 1; i <= 60; ++i) {
    if (i == 19 || i == 20 || i == 21 || i == 26) continue;  // the Schur and right-hand-side layout: ours
    PetscInt value = 0;
    PetscBool set = PETSC_FALSE;
    QV_PETSC(PetscOptionsGetInt(nullptr, "factor_", ("-mat_mumps_icntl_" + std::to_string(i)).c_str(), &value, &set));
    if (set) icntl(id, i) = static_cast<MUMPS_INT>(value);
  }
  for (int i = 1; i <= 15; ++i) {
    PetscReal value = 0;
    PetscBool set = PETSC_FALSE;
    QV_PETSC(PetscOptionsGetReal(nullptr, "factor_", ("-mat_mumps_cntl_" + std::to_string(i)).c_str(), &value, &set));
    if (set) id.cntl[i - 1] = value;
  }
  {
    static const PetscLogEvent event = registerLogEvent("Sequential Cholesky", "SeqCholOrder");  // a -log_view row
    const LogEventScope timed(event);
    const PetscInt ordered = n - schurSize;
    if (icntl(id, 7) == 1) {
      m.perm = nestedDissection(m.upper, ordered, ordered % 3 == 0 ? 3 : 1);
      id.perm_in = m.perm.data();
    }
    for (int& i : m.upper.rows) ++i;
    for (int& j : m.upper.cols) ++j;
    id.n = static_cast<MUMPS_INT>(n);
    id.nnz = static_cast<MUMPS_INT8>(m.upper.values.size());
    id.irn = m.upper.rows.data();
    id.jcn = m.upper.cols.data();
    id.a = m.upper.values.data();
    if (schurSize > 0) {
      for (PetscInt i = ordered; i < n; ++i) m.schurList.push_back(static_cast<MUMPS_INT>(i + 1));
      m.schur = Eigen::MatrixXd::Zero(schurSize, schurSize);
      icntl(id, 19) = 1;  // the Schur complement, centralised on this (the only) process
      id.size_schur = static_cast<MUMPS_INT>(schurSize);
      id.listvar_schur = m.schurList.data();
      id.schur_lld = static_cast<MUMPS_INT>(schurSize);
      id.schur = m.schur.data();
    }
    id.job = kAnalyse;
    dmumps_c(&id);
  }
  if (id.infog[0] < 0) throw std::runtime_error(mumpsError(id, "analysis"));
  std::vector<MUMPS_INT>().swap(m.perm);  // read by the analysis only
  id.perm_in = nullptr;
  factor();
  // The solves read the matrix only to refine or analyse errors.
  if (!refactorable && icntl(id, 10) == 0 && icntl(id, 11) == 0) {
    m.upper = UpperTriangle();
    id.irn = id.jcn = nullptr;
    id.a = nullptr;
  }
}

void SequentialCholesky::factor() {
  Mumps& m = *mumps_;
  DMUMPS_STRUC_C& id = m.id;
  factored_ = false;
  id.job = kFactor;
  {
    static const PetscLogEvent event = registerLogEvent("Sequential Cholesky", "SeqCholFactor");  // a -log_view row
    const LogEventScope timed(event);
    dmumps_c(&id);
  }
  if (id.infog[0] == -10)  // a zero pivot: singular, so not positive definite either
    throw NotPositiveDefinite("the matrix to factor is not positive definite: " + mumpsError(id, "factorization"));
  if (id.infog[0] < 0) throw std::runtime_error(mumpsError(id, "factorization"));
  if (id.infog[11] > 0)
    throw NotPositiveDefinite("the matrix to factor is not positive definite: " + std::to_string(id.infog[11]) +
                              " negative pivots in its Cholesky factorization");
  // MUMPS returns the symmetric Schur complement's lower triangle by rows, the upper one column-major;
  // what it leaves in the other triangle varies (all of it for small complements, zeros for large).
  if (schurSize_ > 0) m.schur.triangularView<Eigen::StrictlyLower>() = m.schur.transpose();
  factored_ = true;
}

void SequentialCholesky::refactor(const std::vector<double>& values) {
  Mumps& m = *mumps_;
  if (!refactorable_) throw std::logic_error("SequentialCholesky: refactor() needs a factor made refactorable");
  if (values.size() != m.upper.values.size())
    throw std::logic_error("SequentialCholesky: refactor() with " + std::to_string(values.size()) + " values for " +
                           std::to_string(m.upper.values.size()) + " entries");
  m.upper.values = values;
  m.id.a = m.upper.values.data();
  if (schurSize_ > 0) {  // into a fresh complement: the last one may have been taken
    m.schur.setZero(schurSize_, schurSize_);
    m.id.schur = m.schur.data();
  }
  factor();
}

SequentialCholesky::~SequentialCholesky() = default;

int SequentialCholesky::orderingUsed() const { return mumps_->id.infog[6]; }

Eigen::MatrixXd SequentialCholesky::takeSchurComplement() {
  if (!factored_) throw std::logic_error("SequentialCholesky: no Schur complement (the last refactor() failed)");
  mumps_->id.schur = nullptr;
  return std::move(mumps_->schur);
}

void SequentialCholesky::solvePhase(double* columns, PetscInt count, int condensation, double* reduced) const {
  if (!factored_) throw std::logic_error("SequentialCholesky: no factor to solve with (the last refactor() failed)");
  if (count <= 0) return;
  if (count > INT_MAX) throw std::runtime_error("SequentialCholesky: too many right-hand sides for one solve");
  DMUMPS_STRUC_C& id = mumps_->id;
  icntl(id, 20) = 0;  // dense right-hand sides, centralised
  icntl(id, 21) = 0;  // the solution overwrites them
  icntl(id, 26) = condensation;
  id.nrhs = static_cast<MUMPS_INT>(count);
  id.lrhs = static_cast<MUMPS_INT>(rows_);
  id.rhs = columns;
  id.redrhs = reduced;
  id.lredrhs = static_cast<MUMPS_INT>(schurSize_);
  id.job = kSolve;
  {
    static const PetscLogEvent event = registerLogEvent("Sequential Cholesky", "SeqCholSolve");  // a -log_view row
    const LogEventScope timed(event);
    dmumps_c(&id);
  }
  if (id.infog[0] < 0) throw std::runtime_error(mumpsError(id, "solve"));
}

void SequentialCholesky::solveInPlace(double* columns, PetscInt count) const {
  if (schurSize_ > 0) throw std::logic_error("SequentialCholesky: a factor with Schur variables solves in two steps");
  solvePhase(columns, count, 0, nullptr);
}

void SequentialCholesky::condense(double* columns, PetscInt count, double* reduced) const {
  if (schurSize_ == 0) throw std::logic_error("SequentialCholesky: no Schur variables to condense on");
  solvePhase(columns, count, 1, reduced);
}

void SequentialCholesky::expand(double* columns, PetscInt count, const double* schurSolution) const {
  if (schurSize_ == 0) throw std::logic_error("SequentialCholesky: no Schur variables to expand from");
  solvePhase(columns, count, 2, const_cast<double*>(schurSolution));  // MUMPS only reads it here
}

} // namespace quiver
