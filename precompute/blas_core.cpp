#include "precompute/blas_core.h"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <cstring>
#include <iostream>

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

// Set by the first run for the second: what OpenBLAS had picked on its own.
constexpr const char* kFirstPick = "QUIVER_BLAS_FIRST_PICK";

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
    line += "; OpenBLAS alone had picked " + std::string(firstPick);
    unsetenv(kFirstPick);
    return line;
  }
  const std::string wanted =
      blasCoreToRequest(cpu, current, std::getenv("QUIVER_BLAS_CORE"), std::getenv("OPENBLAS_CORETYPE"));
  if (wanted.empty()) {
    if (coreVectorLevel(current) < cpu)
      line += "; slower kernels than this CPU can run: OPENBLAS_CORETYPE chose them (unset it, or set QUIVER_BLAS_CORE=auto)";
    return line;
  }
  setenv("OPENBLAS_CORETYPE", wanted.c_str(), 1);
  setenv(kFirstPick, current.c_str(), 1);
  execv("/proc/self/exe", argv);
  // Still here: the program could not be run again; go on with the kernels in use.
  unsetenv(kFirstPick);
  return line + "; could not run again with OPENBLAS_CORETYPE=" + wanted + " (" + std::strerror(errno) + ")";
}

} // namespace quiver
