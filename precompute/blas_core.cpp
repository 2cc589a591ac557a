#include "precompute/blas_core.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdlib>
#include <cstring>

#include <unistd.h>

extern "C" char* openblas_get_corename(void);

namespace quiver {

namespace {

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

const char* levelName(VectorLevel level) {
  switch (level) {
    case VectorLevel::Avx512: return "AVX-512";
    case VectorLevel::Avx2: return "AVX2";
    case VectorLevel::Avx: return "AVX";
    default: return "SSE";
  }
}

// Set by the first run for the second: what OpenBLAS had picked on its own, and what was asked.
constexpr const char* kFirstPick = "QUIVER_BLAS_FIRST_PICK";
constexpr const char* kAsked = "QUIVER_BLAS_ASKED";

} // namespace

VectorLevel cpuVectorLevel() {
#if defined(__x86_64__) && defined(__GNUC__)
  __builtin_cpu_init();
  if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512vl") &&
      __builtin_cpu_supports("avx512dq"))
    return VectorLevel::Avx512;
  if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) return VectorLevel::Avx2;
  if (__builtin_cpu_supports("avx")) return VectorLevel::Avx;
#endif
  return VectorLevel::Baseline;
}

VectorLevel coreVectorLevel(const std::string& core) {
  const std::string c = lower(core);
  for (const char* name : {"skylakex", "cooperlake", "sapphirerapids"})
    if (c == name) return VectorLevel::Avx512;
  for (const char* name : {"haswell", "zen"})
    if (c == name) return VectorLevel::Avx2;
  for (const char* name : {"sandybridge", "bulldozer", "piledriver", "steamroller", "excavator"})
    if (c == name) return VectorLevel::Avx;
  return VectorLevel::Baseline;
}

std::string coreFor(VectorLevel level) {
  switch (level) {
    case VectorLevel::Avx512: return "SkylakeX";
    case VectorLevel::Avx2: return "Haswell";
    case VectorLevel::Avx: return "Sandybridge";
    default: return "";
  }
}

std::string blasCoreToRequest(VectorLevel cpu, const std::string& current, const char* quiverBlasCore,
                              const char* openblasCoretype) {
  const std::string asked = quiverBlasCore ? quiverBlasCore : "";
  if (!asked.empty() && lower(asked) != "auto") return lower(asked) == lower(current) ? "" : asked;
  if (asked.empty() && openblasCoretype && *openblasCoretype) return "";  // the user's own choice
  return coreVectorLevel(current) < cpu ? coreFor(cpu) : "";
}

std::string chooseBlasCore(char** argv) {
  const std::string current = openblas_get_corename();
  const VectorLevel cpu = cpuVectorLevel();
  const char* firstPick = std::getenv(kFirstPick);
  std::string line = "BLAS: OpenBLAS core " + current + " (this CPU: " + levelName(cpu) + ")";
  if (firstPick) {  // the second run: never a third
    const std::string asked = std::getenv(kAsked) ? std::getenv(kAsked) : "";
    line += "; OpenBLAS alone had picked " + std::string(firstPick);
    if (lower(asked) != lower(current))  // this OpenBLAS has no such kernels (or ignores OPENBLAS_CORETYPE)
      line += "; " + asked + " was asked for and is not available";
    unsetenv(kFirstPick);
    unsetenv(kAsked);
    return line;
  }
  const char* quiverCore = std::getenv("QUIVER_BLAS_CORE");
  const char* userCore = std::getenv("OPENBLAS_CORETYPE");
  const std::string wanted = blasCoreToRequest(cpu, current, quiverCore, userCore);
  if (wanted.empty()) {
    if (coreVectorLevel(current) < cpu)
      line += std::string("; slower kernels than this CPU can run: ") +
              (quiverCore && *quiverCore ? "QUIVER_BLAS_CORE" : "OPENBLAS_CORETYPE") + " chose them";
    return line;
  }
  const std::string before = userCore ? userCore : "";
  setenv("OPENBLAS_CORETYPE", wanted.c_str(), 1);
  setenv(kFirstPick, current.c_str(), 1);
  setenv(kAsked, wanted.c_str(), 1);
  execv("/proc/self/exe", argv);
  const int error = errno;
  // Still here: the program could not be run again; go on with the kernels in use, as they were.
  if (userCore)
    setenv("OPENBLAS_CORETYPE", before.c_str(), 1);
  else
    unsetenv("OPENBLAS_CORETYPE");
  unsetenv(kFirstPick);
  unsetenv(kAsked);
  return line + "; could not run again with OPENBLAS_CORETYPE=" + wanted + " (" + std::strerror(error) + ")";
}

} // namespace quiver
