#pragma once
// The bake's process-wide context: MPI, PETSc and SLEPc are initialised for the lifetime of one
// BakeContext, rank 0 speaks for all ranks, and failures end every rank together.
#include <functional>
#include <string>
#include <vector>

#include <mpi.h>

namespace quiver {

class BakeContext {
public:
  // `petscArgs` holds argv[0] plus the PETSc options (-eps_type ..., -log_view, -options_file ...).
  explicit BakeContext(std::vector<std::string> petscArgs);
  ~BakeContext();
  BakeContext(const BakeContext&) = delete;
  BakeContext& operator=(const BakeContext&) = delete;

  MPI_Comm comm() const { return MPI_COMM_WORLD; }
  int rank() const { return rank_; }
  int size() const { return size_; }
  // The cores this rank may run on (its CPU affinity) shared evenly among the ranks of its node, at
  // least one: the threads a stage may run. mpirun binds each rank to a core by default: one.
  int coresPerRank() const { return coresPerRank_; }
  bool quiet = false;

  // Rank 0 prints "quiver-bake: <message>" to stdout unless quiet.
  void progress(const std::string& message) const;

  // Rank 0 warns about PETSc/SLEPc options that nothing read (usually a typo: -eps_tl).
  void warnUnusedOptions() const;

  // Collective: runs `work` on rank 0 only (file writes that one process does for all), then every
  // rank throws std::runtime_error with rank 0's message if it failed, so no rank is left waiting.
  void onRankZero(const std::function<void()>& work) const;

  // Collective: every rank passes its own error ("" for none) and gets back the error of the
  // lowest failing rank, so all ranks fail together with one message and none hangs.
  std::string agreeOnError(const std::string& localError) const;

private:
  std::vector<std::string> argStorage_;
  std::vector<char*> argv_;
  int rank_ = 0, size_ = 1, coresPerRank_ = 1;
};

// The same on any communicator: the lowest failing rank's error, tagged with its rank, on every rank.
std::string firstRankError(const std::string& localError, MPI_Comm comm);
// Collective: throws std::runtime_error with that error on every rank when any rank failed, so
// that none waits for ever in the next collective call.
void throwIfAnyRankFailed(const std::string& localError, MPI_Comm comm);

// Splits a command line into the tool's own options and PETSc's. PETSc options are single-dash
// options with names longer than one letter (-eps_type krylovschur, -log_view), each followed by
// its value when the next word is not itself an option. Both lists start with argv[0].
void splitPetscOptions(int argc, char** argv, std::vector<std::string>& own, std::vector<std::string>& petsc);

} // namespace quiver
