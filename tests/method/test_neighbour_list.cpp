// The cell-list search finds exactly the pairs a brute-force search finds.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "method/NeighbourList.hpp"
#include "model/Errors.hpp"

using namespace tlsph;

namespace {

template <int D>
std::vector<Vec<D>> randomCloud(int n, double extent, std::mt19937& rng) {
  std::uniform_real_distribution<double> unit(0.0, extent);
  std::vector<Vec<D>> X(n);
  for (auto& x : X)
    for (int a = 0; a < D; ++a)
      x[a] = unit(rng);
  return X;
}

template <int D>
void expectMatchesBruteForce(const std::vector<Vec<D>>& X, double H, const PeriodicBox<D>& box) {
  const NeighbourList list = buildNeighbourList<D>(X, H, box);
  const Index n = static_cast<Index>(X.size());
  ASSERT_EQ(list.particleCount(), n);
  for (Index i = 0; i < n; ++i) {
    std::vector<Index> expected;
    for (Index j = 0; j < n; ++j)
      if (j != i && box.separation(X[i], X[j]).norm() < H) expected.push_back(j);
    std::vector<Index> got(list.neighbour.begin() + list.offset[i],
                           list.neighbour.begin() + list.offset[i + 1]);
    ASSERT_EQ(got, expected) << "particle " << i;
  }
}

}  // namespace

TEST(NeighbourList, MatchesBruteForceFree2D) {
  std::mt19937 rng(1);
  expectMatchesBruteForce<2>(randomCloud<2>(600, 1.0, rng), 0.11, {});
}

TEST(NeighbourList, MatchesBruteForceFree3D) {
  std::mt19937 rng(2);
  expectMatchesBruteForce<3>(randomCloud<3>(800, 1.0, rng), 0.19, {});
}

TEST(NeighbourList, MatchesBruteForcePeriodic) {
  std::mt19937 rng(3);
  PeriodicBox<3> box;
  box.periodic = {true, false, true};
  box.length = Vec3(1.0, 0.0, 1.0);
  expectMatchesBruteForce<3>(randomCloud<3>(800, 1.0, rng), 0.23, box);
  PeriodicBox<2> box2;
  box2.periodic = {true, true};
  box2.length = Vec<2>(1.0, 1.0);
  // Support exactly half the period: fewer than three cells per axis.
  expectMatchesBruteForce<2>(randomCloud<2>(300, 1.0, rng), 0.5, box2);
}

TEST(NeighbourList, IsSymmetric) {
  std::mt19937 rng(4);
  const auto X = randomCloud<3>(500, 1.0, rng);
  const auto list = buildNeighbourList<3>(X, 0.2);
  for (Index i = 0; i < list.particleCount(); ++i)
    for (Index k = list.offset[i]; k < list.offset[i + 1]; ++k) {
      const Index j = list.neighbour[k];
      EXPECT_TRUE(std::binary_search(list.neighbour.begin() + list.offset[j],
                                     list.neighbour.begin() + list.offset[j + 1], i));
    }
}

TEST(NeighbourList, RejectsPeriodicBoxSmallerThanTwoSupports) {
  std::mt19937 rng(5);
  PeriodicBox<2> box;
  box.periodic = {true, false};
  box.length = Vec<2>(1.0, 0.0);
  EXPECT_THROW(buildNeighbourList<2>(randomCloud<2>(50, 1.0, rng), 0.6, box), SetupError);
}
