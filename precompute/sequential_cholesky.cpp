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
                                                                            : static_cast<long long>(detail)) + " bytes";
  default:
    return what + "; see the MUMPS users' guide, section \"Error diagnostics\"";
  }
}

// Position of each DOF in a nested-dissection elimination order of the graph whose nodes are
// blocks of `block` consecutive DOFs (a vertex's three), 1-based as MUMPS's PERM_IN wants it.
// METIS's own random choices use a fixed seed: the same order every run.
std::vector<MUMPS_INT> nestedDissection(const std::vector<MUMPS_INT>& rowOf, const std::vector<MUMPS_INT>& colOf,
                                        PetscInt n, PetscInt block) {
  const PetscInt nodes = n / block;
  std::vector<std::vector<idx_t>> neighbours(static_cast<size_t>(nodes));
  for (size_t e = 0; e < rowOf.size(); ++e) {
    const idx_t a = (rowOf[e] - 1) / block, b = (colOf[e] - 1) / block;
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
  idx_t count = static_cast<idx_t>(nodes);
  idx_t options[METIS_NOPTIONS];
  METIS_SetDefaultOptions(options);
  options[METIS_OPTION_NUMBERING] = 0;
  std::vector<idx_t> order(static_cast<size_t>(nodes)), position(static_cast<size_t>(nodes));
  if (METIS_NodeND(&count, offsets.data(), adjacency.data(), nullptr, options, order.data(), position.data()) != METIS_OK)
    throw std::runtime_error("METIS_NodeND failed to order a graph of " + std::to_string(nodes) + " vertices");
  std::vector<MUMPS_INT> perm(static_cast<size_t>(n));
  for (PetscInt i = 0; i < n; ++i)
    perm[i] = static_cast<MUMPS_INT>(block * position[i / block] + i % block + 1);
  return perm;
}

// -log_view rows (PETSc's own MatCholFctrNum and MatMatSolve do not see these calls).
struct LogEvents {
  PetscLogEvent order = 0, factor = 0, solve = 0;
  LogEvents() {
    PetscClassId id = 0;
    PetscClassIdRegister("Sequential Cholesky", &id);
    PetscLogEventRegister("SeqCholOrder", id, &order);
    PetscLogEventRegister("SeqCholFactor", id, &factor);
    PetscLogEventRegister("SeqCholSolve", id, &solve);
  }
};
const LogEvents& events() {
  static const LogEvents instance;
  return instance;
}

} // namespace

struct SequentialCholesky::Mumps {
  DMUMPS_STRUC_C id{};
  std::vector<MUMPS_INT> rows, cols, perm;  // A's upper triangle (1-based), the elimination order
  std::vector<double> values;
  bool initialised = false;
  ~Mumps() {
    if (!initialised) return;
    id.job = kEnd;
    dmumps_c(&id);
  }
};

SequentialCholesky::SequentialCholesky(Mat A) : mumps_(std::make_unique<Mumps>()) {
  PetscInt n = 0, columns = 0;
  QV_PETSC(MatGetSize(A, &n, &columns));
  PetscInt start = 0, end = 0;
  QV_PETSC(MatGetOwnershipRange(A, &start, &end));
  if (start != 0 || end != n || n != columns)
    throw std::logic_error("SequentialCholesky: the matrix must be square and held whole on this rank");
  if (n > INT_MAX) throw std::runtime_error("SequentialCholesky: " + std::to_string(n) + " rows exceed MUMPS's int");
  rows_ = n;
  Mumps& m = *mumps_;
  for (PetscInt i = 0; i < n; ++i) {
    PetscInt length = 0;
    const PetscInt* cols = nullptr;
    const PetscScalar* values = nullptr;
    QV_PETSC(MatGetRow(A, i, &length, &cols, &values));
    for (PetscInt e = 0; e < length; ++e)
      if (cols[e] >= i) {
        m.rows.push_back(static_cast<MUMPS_INT>(i + 1));
        m.cols.push_back(static_cast<MUMPS_INT>(cols[e] + 1));
        m.values.push_back(values[e]);
      }
    QV_PETSC(MatRestoreRow(A, i, &length, &cols, &values));
  }

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
  id.n = static_cast<MUMPS_INT>(n);
  id.nnz = static_cast<MUMPS_INT8>(m.values.size());
  id.irn = m.rows.data();
  id.jcn = m.cols.data();
  id.a = m.values.data();
  PetscLogEventBegin(events().order, 0, 0, 0, 0);
  if (icntl(id, 7) == 1) {
    m.perm = nestedDissection(m.rows, m.cols, n, n % 3 == 0 ? 3 : 1);
    id.perm_in = m.perm.data();
  }
  id.job = kAnalyse;
  dmumps_c(&id);
  PetscLogEventEnd(events().order, 0, 0, 0, 0);
  if (id.infog[0] < 0) throw std::runtime_error(mumpsError(id, "analysis"));
  id.job = kFactor;
  PetscLogEventBegin(events().factor, 0, 0, 0, 0);
  dmumps_c(&id);
  PetscLogEventEnd(events().factor, 0, 0, 0, 0);
  if (id.infog[0] < 0) throw std::runtime_error(mumpsError(id, "factorization"));
  if (id.infog[11] > 0)
    throw std::runtime_error("the matrix to factor is not positive definite: " + std::to_string(id.infog[11]) +
                             " negative pivots in its Cholesky factorization");
}

SequentialCholesky::~SequentialCholesky() = default;

int SequentialCholesky::orderingUsed() const { return mumps_->id.infog[6]; }

void SequentialCholesky::solveInPlace(double* columns, PetscInt count) const {
  if (count <= 0) return;
  if (count > INT_MAX) throw std::runtime_error("SequentialCholesky: too many right-hand sides for one solve");
  DMUMPS_STRUC_C& id = mumps_->id;
  id.icntl[19] = 0;  // ICNTL(20): dense right-hand sides, centralised
  id.icntl[20] = 0;  // ICNTL(21): the solution overwrites them
  id.nrhs = static_cast<MUMPS_INT>(count);
  id.lrhs = static_cast<MUMPS_INT>(rows_);
  id.rhs = columns;
  id.job = kSolve;
  PetscLogEventBegin(events().solve, 0, 0, 0, 0);
  dmumps_c(&id);
  PetscLogEventEnd(events().solve, 0, 0, 0, 0);
  if (id.infog[0] < 0) throw std::runtime_error(mumpsError(id, "solve"));
}

} // namespace quiver
