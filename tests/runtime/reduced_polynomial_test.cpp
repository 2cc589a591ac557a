// The reduced polynomial's two layouts (one state's packed symmetric product, the groups' two-pass
// contraction) and its energy alone (summed from the monomials) against the energy differentiated
// monomial by monomial, for bases small enough to leave blocks of eight partly filled or to have a
// single pair.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "formats/model/qvr.h"
#include "runtime/src/reduced_polynomial.h"

namespace {

using quiver::rt::ReducedPolynomial;

struct AlignedFree {
  void operator()(void* p) const { std::free(p); }
};
std::unique_ptr<void, AlignedFree> aligned(size_t bytes) {
  return std::unique_ptr<void, AlignedFree>(std::aligned_alloc(64, (bytes + 63) / 64 * 64));
}

// E(q), its gradient and its Hessian from the monomial coefficients (the .qvr order: degree 2, 3,
// 4, each over sorted index tuples), each monomial differentiated as a product of its factors.
struct Reference {
  double energy = 0;
  std::vector<double> gradient, hessian;
  Reference(int r, const std::vector<double>& c, const std::vector<double>& q) : gradient(r), hessian(r * r) {
    size_t at = 0;
    std::vector<int> idx;
    const auto visit = [&](auto&& self, int degree, int from) -> void {
      if (static_cast<int>(idx.size()) == degree) {
        add(c[at++], idx, q, r);
        return;
      }
      for (int i = from; i < r; ++i) {
        idx.push_back(i);
        self(self, degree, i);
        idx.pop_back();
      }
    };
    for (int degree = 2; degree <= 4; ++degree) visit(visit, degree, 0);
  }
  // c times the product of q over idx, and its first and second derivatives (one factor taken
  // out per position; two distinct positions for the second).
  void add(double c, const std::vector<int>& idx, const std::vector<double>& q, int r) {
    const size_t n = idx.size();
    const auto productWithout = [&](size_t a, size_t b) {
      double p = c;
      for (size_t s = 0; s < n; ++s)
        if (s != a && s != b) p *= q[idx[s]];
      return p;
    };
    energy += productWithout(n, n);
    for (size_t a = 0; a < n; ++a) {
      gradient[idx[a]] += productWithout(a, n);
      for (size_t b = 0; b < n; ++b)
        if (b != a) hessian[idx[a] * r + idx[b]] += productWithout(a, b);
    }
  }
};

double largest(const std::vector<double>& x) {
  double m = 0;
  for (double v : x) m = std::max(m, std::abs(v));
  return m;
}

} // namespace

// float32 coefficients: within 1e-6 of the exact values (the coefficients' rounding, summed), and
// the two layouts and the energy alone within 1e-13 of each other (the same rounded coefficients).
TEST(ReducedPolynomial, BothLayoutsAgreeWithTheEnergyDifferentiatedTermByTerm) {
  std::mt19937 rng(7);
  std::normal_distribution<double> n(0, 1);
  constexpr int L = ReducedPolynomial::kLanes;
  for (bool single : {false, true})
  for (int r : {1, 2, 3, 7, 8, 9, 17}) {
    std::vector<double> c(quiver::energyCoefficientCount(r));
    for (double& x : c) x = n(rng);
    auto storage = aligned(ReducedPolynomial::storageBytes(r, single, true));
    ReducedPolynomial poly;
    poly.build(r, c.data(), single, true, storage.get());
    std::vector<double> oneScratch(ReducedPolynomial::scratchSize(r));
    auto laneScratch = aligned(ReducedPolynomial::laneScratchSize(r) * sizeof(double));
    std::vector<std::vector<double>> q(L, std::vector<double>(r)), f(L, std::vector<double>(r));
    std::vector<const double*> at(L);
    std::vector<double*> forces(L);
    for (int l = 0; l < L; ++l) {
      for (double& x : q[l]) x = 0.3 * n(rng);
      at[l] = q[l].data(), forces[l] = f[l].data();
    }
    std::vector<double> lanes(quiver::monomialCount2(r) * L);
    double energy[L];
    for (int count : {1, 5, L}) {  // a partial group too: the unused lanes must not leak in
      poly.evaluateLanes(at.data(), count, energy, forces.data(), lanes.data(), static_cast<double*>(laneScratch.get()));
      for (int l = 0; l < count; ++l) {
        const Reference exact(r, c, q[l]);
        const double scale = std::max(1.0, largest(exact.hessian)), tolerance = (single ? 1e-6 : 1e-13) * scale;
        const double agree = 1e-13 * scale;  // one layout against the other
        double e1 = 0;
        std::vector<double> f1(r), K1(r * r);
        poly.evaluate(q[l].data(), &e1, f1.data(), K1.data(), oneScratch.data());
        const std::string where = std::string(single ? "float32" : "float64") + ", r = " + std::to_string(r) +
                                  ", lane " + std::to_string(l);
        EXPECT_NEAR(e1, exact.energy, tolerance) << where;
        EXPECT_NEAR(energy[l], e1, agree) << where;
        double alone = 0;  // summed from the monomials: the same rounded coefficients
        poly.evaluate(q[l].data(), &alone, nullptr, nullptr, oneScratch.data());
        EXPECT_NEAR(alone, exact.energy, tolerance) << where;
        EXPECT_NEAR(alone, e1, agree) << where;
        for (int a = 0, p = 0; a < r; ++a) {
          EXPECT_NEAR(f1[a], exact.gradient[a], tolerance) << where << ", a = " << a;
          EXPECT_NEAR(f[l][a], f1[a], agree) << where << ", a = " << a;
          for (int b = a; b < r; ++b, ++p) {
            EXPECT_NEAR(K1[a * r + b], exact.hessian[a * r + b], tolerance) << where << ", K" << a << b;
            EXPECT_NEAR(lanes[p * L + l], K1[a * r + b], agree) << where << ", K" << a << b;
          }
        }
      }
    }
  }
}
