#pragma once
// Which OpenBLAS kernels the bake runs on. Debian's OpenBLAS (DYNAMIC_ARCH) picks its kernel set
// from the CPU's model number when the library loads, before main. A model it does not know (an
// Intel Xeon newer than the library, such as family 6 model 207 under OpenBLAS 0.3.21) gets the
// SSE3 "Prescott" kernels: the polynomial stage's dsyrk runs 2-3x slower, and PETSc and MUMPS use
// the same BLAS. The kernel set can only be chosen before the library loads (OPENBLAS_CORETYPE),
// so quiver-bake checks first thing whether the kernels in use match the CPU's vector features
// and, when they are weaker, runs itself again with OPENBLAS_CORETYPE naming the right ones.
//
// QUIVER_BLAS_CORE in the environment: unset, the bake chooses unless OPENBLAS_CORETYPE is set
// (then that is respected); "auto", the bake chooses even then; a core name, that core.
#include <string>

namespace quiver {

// Vector extensions, by what OpenBLAS's kernel sets use.
enum class VectorLevel { Baseline = 0, Avx = 1, Avx2 = 2, Avx512 = 3 };

VectorLevel cpuVectorLevel();
// The level of an OpenBLAS core name (as openblas_get_corename() gives it; any case).
VectorLevel coreVectorLevel(const std::string& core);
// The core to ask for on a CPU of `level`: SkylakeX, Haswell, Sandybridge, or "" (none better).
std::string coreFor(VectorLevel level);

// The core to request through OPENBLAS_CORETYPE, or "" to keep `current`, given the CPU's level and
// the environment's QUIVER_BLAS_CORE and OPENBLAS_CORETYPE (null when unset).
std::string blasCoreToRequest(VectorLevel cpu, const std::string& current, const char* quiverBlasCore,
                              const char* openblasCoretype);

// First thing in main: when blasCoreToRequest() asks for a core, sets OPENBLAS_CORETYPE and runs
// the program again (execv of /proc/self/exe with the same argv, once). Returns a line for the log:
// the core in use and why.
std::string chooseBlasCore(char** argv);

} // namespace quiver
