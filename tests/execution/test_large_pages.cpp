// The per-pair arrays' storage (LargePageAllocator.hpp): a block of 2 MiB or more
// starts on a 2 MiB boundary in a mapping advised for huge pages, smaller blocks keep their
// type's alignment, and the arrays behave as vectors (growth across the threshold, copies,
// moves); the reference configuration's per-pair arrays and the per-particle arrays the pair
// loops gather live in such blocks. That the kernel then backs them with huge pages is its
// choice (printed, not asserted).
#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>
#include <numeric>
#include <string>

#include "TestSupport.hpp"
#include "execution/LargePageAllocator.hpp"
#include "fast/TaylorQuadrature.hpp"
#include "method/ReferenceConfiguration.hpp"

using namespace tlsph;
using namespace tlsph::testing;

namespace {

bool alignedTo(const void* p, std::size_t alignment) {
  return reinterpret_cast<std::uintptr_t>(p) % alignment == 0;
}

// madvise(MADV_HUGEPAGE) is refused only where the kernel has no transparent huge pages; with
// them "never" it is accepted but does nothing.
bool kernelHasHugePages() {
#if defined(__linux__)
  std::ifstream setting("/sys/kernel/mm/transparent_hugepage/enabled");
  std::string line;
  return std::getline(setting, line) && line.find("[never]") == std::string::npos;
#else
  return false;
#endif
}

}  // namespace

TEST(LargePages, BigBlockIsAlignedAndAdvised) {
  const std::size_t n = (3 << 20) / sizeof(double) + 5;  // 3 MiB and a bit
  PairArray<double> a(n);
  EXPECT_TRUE(alignedTo(a.data(), largepages::kHugePageBytes));
  std::iota(a.begin(), a.end(), 0.0);
  EXPECT_EQ(a.front(), 0.0);
  EXPECT_EQ(a.back(), double(n - 1));
  if (!kernelHasHugePages()) GTEST_SKIP() << "no transparent huge pages in this kernel";
  const auto map = largepages::mappingOf(a.data());
  ASSERT_TRUE(map.found);
  EXPECT_TRUE(map.advised);
  EXPECT_GE(map.bytes, n * sizeof(double));
  std::cout << "3 MiB pair array: " << map.hugePageBytes / 1024
            << " KiB of its mapping on huge pages\n";
}

TEST(LargePages, SmallBlocksKeepTheirTypesAlignment) {
  using Sym = TaylorQuadrature<3>::Sym;  // an Eigen type with its own alignment
  PairArray<Sym> s(7, Sym::Constant(2.0));
  EXPECT_TRUE(alignedTo(s.data(), alignof(Sym)));
  PairArray<Vec3> v(3, Vec3(1.0, 2.0, 3.0));
  EXPECT_EQ(v[2], Vec3(1.0, 2.0, 3.0));
  const auto map = largepages::mappingOf(s.data());
  EXPECT_FALSE(map.found && map.advised && alignedTo(s.data(), largepages::kHugePageBytes));
}

TEST(LargePages, VectorsGrowCopyAndMoveAcrossTheThreshold) {
  PairArray<Vec3> a;
  const int n = 200000;  // 4.8 MB: several reallocations below and above 2 MiB
  for (int i = 0; i < n; ++i)
    a.push_back(Vec3(i, -i, 0.5 * i));
  ASSERT_EQ(a.size(), std::size_t(n));
  EXPECT_TRUE(alignedTo(a.data(), largepages::kHugePageBytes));
  for (int i = 0; i < n; i += 997)
    EXPECT_EQ(a[i], Vec3(i, -i, 0.5 * i));
  PairArray<Vec3> copy = a;
  EXPECT_EQ(copy, a);
  EXPECT_NE(copy.data(), a.data());
  const Vec3* before = a.data();
  PairArray<Vec3> moved = std::move(a);
  EXPECT_EQ(moved.data(), before);
  EXPECT_EQ(moved, copy);
  moved.resize(10);  // shrinking keeps the block; shrink_to_fit gives a small one back
  moved.shrink_to_fit();
  EXPECT_EQ(moved[9], Vec3(9, -9, 4.5));
  EXPECT_FALSE(alignedTo(moved.data(), largepages::kHugePageBytes) &&
               largepages::mappingOf(moved.data()).advised);
}

// The arrays the pair loops stream live in such blocks once they are big enough.
TEST(LargePages, ReferenceConfigurationsPairArraysAreAdvised) {
  const double dx = 0.01;
  const auto X = cellCentredLattice<3>(Vec3::Zero(), {40, 12, 12}, dx);  // 5,760 particles
  const std::vector<double> volume(X.size(), dx * dx * dx);
  const auto ref =
      buildReferenceConfiguration<3>(X, volume, Kernel<3>(KernelType::WendlandC2, 2.1 * dx));
  ASSERT_GE(ref.correctedGradient.size() * sizeof(Vec3), largepages::kHugePageBytes);
  for (const void* p : {static_cast<const void*>(ref.correctedGradient.data()),
                        static_cast<const void*>(ref.reverseGradient.data()),
                        static_cast<const void*>(ref.separation.data())})
    EXPECT_TRUE(alignedTo(p, largepages::kHugePageBytes));
  if (!kernelHasHugePages()) GTEST_SKIP() << "no transparent huge pages in this kernel";
  EXPECT_TRUE(largepages::mappingOf(ref.correctedGradient.data()).advised);
}

// So do the per-particle arrays the pair loops gather at the neighbours' indices (F here).
TEST(LargePages, GatheredParticleArraysAreAdvised) {
  const double dx = 0.01;
  const auto X = cellCentredLattice<3>(Vec3::Zero(), {32, 32, 32}, dx);  // F: 2.4 MB
  const std::vector<double> volume(X.size(), dx * dx * dx);
  const auto ref =
      buildReferenceConfiguration<3>(X, volume, Kernel<3>(KernelType::WendlandC2, 2.1 * dx));
  const std::vector<Material> materials{testMaterial("neo-hookean")};
  const std::vector<std::uint16_t> materialOf(X.size(), 0);
  TlsphForces<3> forces(ref, materials, materialOf, volume, HourglassSettings{});
  const auto& F = forces.deformationGradient();
  ASSERT_GE(F.size() * sizeof(Mat3), largepages::kHugePageBytes);
  EXPECT_TRUE(alignedTo(F.data(), largepages::kHugePageBytes));
  if (!kernelHasHugePages()) GTEST_SKIP() << "no transparent huge pages in this kernel";
  EXPECT_TRUE(largepages::mappingOf(F.data()).advised);
}
