#include "precompute/bake_context.h"

#include <algorithm>
#include <cctype>
#include <iostream>
#include <stdexcept>

#include <sched.h>

#include <cblas.h>
#include <slepcsys.h>

#include "precompute/child_process.h"

namespace quiver {

namespace {
bool isPetscOption(const std::string& a) {
  return a.size() > 2 && a[0] == '-' && a[1] != '-' && std::isalpha(static_cast<unsigned char>(a[1]));
}
bool looksLikeOption(const std::string& a) {
  return a.size() > 1 && a[0] == '-' && !std::isdigit(static_cast<unsigned char>(a[1])) && a[1] != '.';
}
} // namespace

void splitPetscOptions(int argc, char** argv, std::vector<std::string>& own, std::vector<std::string>& petsc) {
  own.assign(1, argv[0]);
  petsc.assign(1, argv[0]);
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    if (!isPetscOption(a)) {
      own.push_back(a);
      continue;
    }
    petsc.push_back(a);
    if (i + 1 < argc && !looksLikeOption(argv[i + 1])) petsc.push_back(argv[++i]);
  }
}

BakeContext::BakeContext(std::vector<std::string> petscArgs) : argStorage_(std::move(petscArgs)) {
  for (auto& a : argStorage_) argv_.push_back(a.data());
  argv_.push_back(nullptr);
  int argc = static_cast<int>(argStorage_.size());
  char** argv = argv_.data();
  if (SlepcInitialize(&argc, &argv, nullptr, nullptr) != 0) throw std::runtime_error("SLEPc/PETSc initialisation failed");
  MPI_Comm_rank(comm(), &rank_);
  MPI_Comm_size(comm(), &size_);
  // Parallelism comes from the ranks, and from the threads of the stages that start their own
  // (coresPerRank()); BLAS threads on top would oversubscribe.
  openblas_set_num_threads(1);
  MPI_Comm node;
  MPI_Comm_split_type(comm(), MPI_COMM_TYPE_SHARED, rank_, MPI_INFO_NULL, &node);
  int ranksOnNode = 1;
  MPI_Comm_size(node, &ranksOnNode);
  MPI_Comm_free(&node);
  cpu_set_t cores;
  if (sched_getaffinity(0, sizeof cores, &cores) == 0) coresPerRank_ = std::max(1, CPU_COUNT(&cores) / ranksOnNode);
}

BakeContext::~BakeContext() { SlepcFinalize(); }

void BakeContext::progress(const std::string& message) const {
  if (rank_ == 0 && !quiet) std::cout << "quiver-bake: " << message << std::endl;
}

void BakeContext::warnUnusedOptions() const {
  PetscInt count = 0;
  char** names = nullptr;
  char** values = nullptr;
  if (PetscOptionsLeftGet(nullptr, &count, &names, &values) != 0) return;
  for (PetscInt i = 0; i < count; ++i)
    if (rank_ == 0) std::cerr << "quiver-bake: warning: option -" << names[i] << " was not used (misspelt?)" << std::endl;
  PetscOptionsLeftRestore(nullptr, &count, &names, &values);
}

void BakeContext::onRankZero(const std::function<void()>& work) const {
  std::string error;
  if (rank_ == 0) {
    try {
      work();
    } catch (const Interrupted&) {
      throw;  // the bake ends as signalled, agreeing on nothing (child_process.h, quiver-bake's main)
    } catch (const std::exception& e) {
      error = e.what();
      if (error.empty()) error = "unknown error";
    }
  }
  error = agreeOnError(error);
  if (!error.empty()) throw std::runtime_error(error);
}

void throwIfAnyRankFailed(const std::string& localError, MPI_Comm comm) {
  const std::string first = firstRankError(localError, comm);
  if (!first.empty()) throw std::runtime_error(first);
}

std::string BakeContext::agreeOnError(const std::string& localError) const {
  return firstRankError(localError, comm());
}

std::string firstRankError(const std::string& localError, MPI_Comm comm) {
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  int mine = localError.empty() ? size : rank, first = size;
  MPI_Allreduce(&mine, &first, 1, MPI_INT, MPI_MIN, comm);
  if (first == size) return "";
  int length = static_cast<int>(localError.size());
  MPI_Bcast(&length, 1, MPI_INT, first, comm);
  std::string message = rank == first ? localError : std::string(length, ' ');
  MPI_Bcast(message.data(), length, MPI_CHAR, first, comm);
  return first > 0 ? message + " (rank " + std::to_string(first) + ")" : message;
}

} // namespace quiver
