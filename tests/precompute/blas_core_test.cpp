// The choice of OpenBLAS kernels (precompute/blas_core.h): names to levels, and when to ask.
#include <gtest/gtest.h>

#include "precompute/blas_core.h"

using quiver::VectorLevel;

TEST(BlasCore, CoreNamesHaveTheLevelsOfTheirKernels) {
  EXPECT_EQ(quiver::coreVectorLevel("SkylakeX"), VectorLevel::Avx512);
  EXPECT_EQ(quiver::coreVectorLevel("Cooperlake"), VectorLevel::Avx512);
  EXPECT_EQ(quiver::coreVectorLevel("HASWELL"), VectorLevel::Avx2);
  EXPECT_EQ(quiver::coreVectorLevel("Zen"), VectorLevel::Avx2);
  EXPECT_EQ(quiver::coreVectorLevel("Sandybridge"), VectorLevel::Avx);
  EXPECT_EQ(quiver::coreVectorLevel("Prescott"), VectorLevel::Baseline);
  EXPECT_EQ(quiver::coreVectorLevel("Nehalem"), VectorLevel::Baseline);
  for (VectorLevel level : {VectorLevel::Avx, VectorLevel::Avx2, VectorLevel::Avx512})
    EXPECT_EQ(quiver::coreVectorLevel(quiver::coreFor(level)), level);  // asking for a level's core gets that level
  EXPECT_EQ(quiver::coreFor(VectorLevel::Baseline), "");
}

TEST(BlasCore, AsksOnlyWhenTheKernelsAreWeakerThanTheCpuOrTheUserSaysSo) {
  // OpenBLAS did not know the CPU (the Xeon): ask for AVX-512 kernels.
  EXPECT_EQ(quiver::blasCoreToRequest(VectorLevel::Avx512, "Prescott", nullptr, nullptr), "SkylakeX");
  EXPECT_EQ(quiver::blasCoreToRequest(VectorLevel::Avx2, "Prescott", nullptr, nullptr), "Haswell");
  // It did: leave it.
  EXPECT_EQ(quiver::blasCoreToRequest(VectorLevel::Avx512, "Cooperlake", nullptr, nullptr), "");
  EXPECT_EQ(quiver::blasCoreToRequest(VectorLevel::Avx2, "Zen", nullptr, nullptr), "");
  EXPECT_EQ(quiver::blasCoreToRequest(VectorLevel::Baseline, "Prescott", nullptr, nullptr), "");
  // The user's OPENBLAS_CORETYPE is theirs, unless QUIVER_BLAS_CORE=auto overrides it.
  EXPECT_EQ(quiver::blasCoreToRequest(VectorLevel::Avx512, "Prescott", nullptr, "Prescott"), "");
  EXPECT_EQ(quiver::blasCoreToRequest(VectorLevel::Avx512, "Prescott", "auto", "Prescott"), "SkylakeX");
  EXPECT_EQ(quiver::blasCoreToRequest(VectorLevel::Avx512, "Prescott", "", nullptr), "SkylakeX");
  // A named core is asked for unless it is the one in use.
  EXPECT_EQ(quiver::blasCoreToRequest(VectorLevel::Avx512, "Cooperlake", "Haswell", nullptr), "Haswell");
  EXPECT_EQ(quiver::blasCoreToRequest(VectorLevel::Avx512, "Haswell", "haswell", nullptr), "");
}
