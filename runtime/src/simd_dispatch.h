#pragma once
// QV_HOT marks a hot loop for AVX-512 and AVX2 versions chosen at run time where the compiler
// supports it; define QUIVER_CROSS_PLATFORM_DETERMINISTIC to keep one code path (and so the same
// bits) on every x86-64 machine.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && defined(__ELF__) && \
    !defined(QUIVER_CROSS_PLATFORM_DETERMINISTIC)
#define QV_HOT __attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")))
#else
#define QV_HOT
#endif
