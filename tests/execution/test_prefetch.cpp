// Prefetching the pair loops' gathers (Prefetch.hpp): a hint only, so the forces are
// bit for bit those without it; the rule that turns it on reads the machine's last-level cache.
#include <gtest/gtest.h>

#include <cstring>
#include <random>
#include <vector>

#include "TestSupport.hpp"
#include "execution/Prefetch.hpp"
#include "fast/TlsphForces.hpp"

using namespace tlsph;
using namespace tlsph::testing;

TEST(Prefetch, CacheSizesAsLinuxWritesThem) {
  EXPECT_EQ(parseCacheSize("32768K"), std::size_t(32) << 20);
  EXPECT_EQ(parseCacheSize("1M"), std::size_t(1) << 20);
  EXPECT_EQ(parseCacheSize("2G"), std::size_t(2) << 30);
  EXPECT_EQ(parseCacheSize("512"), 512u);
  EXPECT_EQ(parseCacheSize("48K\n"), std::size_t(48) << 10);
  EXPECT_EQ(parseCacheSize(""), 0u);
  EXPECT_EQ(parseCacheSize("K"), 0u);
  EXPECT_EQ(parseCacheSize("12X"), 0u);
}

TEST(Prefetch, TheRuleComparesWithTwiceTheLastLevelCache) {
  const std::size_t llc = lastLevelCacheBytes();
  EXPECT_GE(llc, std::size_t(64) << 10);  // every machine this runs on has one this large
  EXPECT_FALSE(gathersFromMemory(2.0 * double(llc)));
  EXPECT_TRUE(gathersFromMemory(2.0 * double(llc) + 1.0));
}

namespace {

template <int D>
void expectSameForcesWithPrefetch(Quadrature quadrature, GradientCorrection correction,
                                  const HourglassSettings& hourglass) {
  const double dx = 0.01;
  std::array<int, D> counts;
  counts.fill(6);
  counts[0] = 12;
  const auto X = cellCentredLattice<D>(Vec<D>::Zero(), counts, dx);
  const Index n = static_cast<Index>(X.size());
  const std::vector<double> V(n, std::pow(dx, D));
  const std::vector<Material> materials{testMaterial("neo-hookean")};
  const std::vector<std::uint16_t> materialOf(n, 0);
  const auto ref = buildReferenceConfiguration<D>(X, V, Kernel<D>(KernelType::WendlandC2, 2.1 * dx),
                                                  {}, correction);
  std::mt19937 rng(7);
  std::vector<Vec<D>> u(n);
  for (Index i = 0; i < n; ++i)
    u[i] = 0.2 * X[i].cwiseProduct(X[i]) + randomVector<D>(rng, 0.01 * dx);
  TlsphForces<D> plain(ref, materials, materialOf, V, hourglass, quadrature);
  TlsphForces<D> prefetching(ref, materials, materialOf, V, hourglass, quadrature);
  EXPECT_FALSE(plain.prefetchGathers());  // a few hundred particles sit in any cache
  prefetching.prefetchGathers(true);
  std::vector<Vec<D>> a(n), b(n);
  plain.compute(u, a);
  prefetching.compute(u, b);
  for (Index i = 0; i < n; ++i)
    ASSERT_EQ(std::memcmp(a[i].data(), b[i].data(), sizeof(Vec<D>)), 0) << i;
  EXPECT_GT(a[n / 2].norm(), 0.0);
}

}  // namespace

TEST(Prefetch, ForcesAreTheSameBitForBit) {
  const HourglassSettings energy{10.0, HourglassForm::Energy, HourglassGradient::Corrected};
  const HourglassSettings linearF{10.0, HourglassForm::Energy, HourglassGradient::Linear};
  const HourglassSettings textbook{2.0, HourglassForm::Ganzenmueller, HourglassGradient::Corrected};
  for (const auto& hourglass : {energy, linearF, textbook}) {
    expectSameForcesWithPrefetch<2>(Quadrature::Taylor, GradientCorrection::Quadratic, hourglass);
    expectSameForcesWithPrefetch<3>(Quadrature::Taylor, GradientCorrection::Quadratic, hourglass);
    expectSameForcesWithPrefetch<3>(Quadrature::Nodal, GradientCorrection::Linear, hourglass);
  }
}
