#pragma once
// QV_HOT marks a hot loop for AVX-512 and AVX2 versions chosen at run time where the compiler
// supports it; define QUIVER_CROSS_PLATFORM_DETERMINISTIC to keep one code path (and so the same
// bits) on every x86-64 machine.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && defined(__ELF__) && \
    !defined(QUIVER_CROSS_PLATFORM_DETERMINISTIC)
#define QV_HOT __attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")))
#define QV_VECTOR_REGISTERS_32 __builtin_cpu_supports("x86-64-v4")
#else
#define QV_HOT
#define QV_VECTOR_REGISTERS_32 false
#endif

namespace quiver::rt {

// Whether a QV_HOT function runs as its AVX-512 version, the one with 32 vector registers: a
// kernel that keeps many running sums in registers takes fewer at a time in the others, which
// have 16 and would spill them to the stack on every multiply-add.
inline bool vectorRegisters32() { return QV_VECTOR_REGISTERS_32; }

} // namespace quiver::rt
