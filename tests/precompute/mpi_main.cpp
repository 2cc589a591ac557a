// main() of the bake's tests: they run under mpirun (1 and 2 ranks), with MPI, and PETSc and
// SLEPc on top of it (the bake's stages are PETSc code), initialised around the whole run. Rank 0
// prints GoogleTest's usual report; the other ranks print only their own failures, prefixed with
// the rank, and every rank returns the same exit code.
#include <gtest/gtest.h>
#include <mpi.h>
#include <slepcsys.h>

#include <iostream>

namespace {

class RankFailurePrinter : public ::testing::EmptyTestEventListener {
public:
  explicit RankFailurePrinter(int rank) : rank_(rank) {}
  void OnTestPartResult(const ::testing::TestPartResult& result) override {
    if (result.failed())
      std::cout << "[rank " << rank_ << "] " << (result.file_name() ? result.file_name() : "?") << ':'
                << result.line_number() << ": " << result.summary() << std::endl;
  }

private:
  int rank_;
};

} // namespace

// OpenBLAS (linked through quiver_precompute): one thread per rank, as the bake runs it.
extern "C" void openblas_set_num_threads(int);

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  openblas_set_num_threads(1);
  ::testing::InitGoogleTest(&argc, argv);  // takes its --gtest_* flags; PETSc options stay for PETSc
  if (SlepcInitialize(&argc, &argv, nullptr, nullptr) != 0) {
    std::cerr << "SLEPc/PETSc initialisation failed" << std::endl;
    MPI_Abort(MPI_COMM_WORLD, 1);
  }
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  if (rank != 0) {
    ::testing::TestEventListeners& listeners = ::testing::UnitTest::GetInstance()->listeners();
    delete listeners.Release(listeners.default_result_printer());
    listeners.Append(new RankFailurePrinter(rank));
  }
  int failed = RUN_ALL_TESTS() != 0, anyFailed = 0;
  MPI_Allreduce(&failed, &anyFailed, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  if (rank == 0 && anyFailed && !failed)
    std::cout << "FAILED on another rank: see its [rank N] lines above" << std::endl;
  SlepcFinalize();  // leaves MPI alone: PETSc did not initialise it
  MPI_Finalize();
  return anyFailed;
}
