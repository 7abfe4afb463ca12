// Splitting the particles among ranks (DomainPartition): every particle owned once,
// the halo exactly the other parts' particles that the owned ones read, the parts balanced,
// the same partition on every call, and of the two partitioners the one with the smaller halo
// kept.
#include <gtest/gtest.h>

#include <algorithm>
#include <iostream>
#include <set>

#include "distributed/DomainPartition.hpp"
#include "geometry/Lattice.hpp"

using namespace tlsph;

namespace {

void expectConsistent(const DomainPartition& p, const NeighbourList& nb) {
  const Index n = nb.particleCount();
  ASSERT_EQ(static_cast<Index>(p.part.size()), n);
  ASSERT_EQ(static_cast<int>(p.owned.size()), p.parts);
  std::vector<int> seen(n, 0);
  for (int q = 0; q < p.parts; ++q) {
    EXPECT_FALSE(p.owned[q].empty()) << p.method << " part " << q;
    for (Index i : p.owned[q]) {
      ++seen[i];
      EXPECT_EQ(p.part[i], q);
    }
    // The halo by its definition.
    std::set<Index> halo;
    for (Index i : p.owned[q])
      for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k)
        if (p.part[nb.neighbour[k]] != q) halo.insert(nb.neighbour[k]);
    EXPECT_EQ(std::vector<Index>(halo.begin(), halo.end()), p.halo[q]) << p.method << " " << q;
  }
  for (Index i = 0; i < n; ++i)
    ASSERT_EQ(seen[i], 1) << "particle " << i;
}

TEST(DomainPartition, BisectionCutsABeamAcrossItsLength) {
  // 80 x 8 x 8 particles, support 2.1 dx: two parts meet at mid-length, and each reads the
  // other's two nearest layers of 64 particles.
  const double dx = 0.01;
  const auto X = cellCentredLattice<3>(Vec<3>::Zero(), {80, 8, 8}, dx);
  const NeighbourList nb = buildNeighbourList<3>(X, 2.1 * dx);
  const DomainPartition p = partitionByBisection<3>(X, nb, 2);
  expectConsistent(p, nb);
  EXPECT_EQ(p.owned[0].size(), 40u * 64u);
  EXPECT_EQ(p.halo[0].size(), 128u);
  EXPECT_EQ(p.halo[1].size(), 128u);
  for (Index i : p.owned[0])
    EXPECT_LT(X[i].x(), 0.4);
  EXPECT_LT(p.imbalance(nb), 1.0 + 1e-12);
}

TEST(DomainPartition, PartsAreBalancedAndHalosExact) {
  const double dx = 0.01;
  const auto plate = cellCentredLattice<3>(Vec<3>::Zero(), {40, 40, 4}, dx);
  const auto square = cellCentredLattice<2>(Vec<2>::Zero(), {60, 45}, dx);
  const NeighbourList nb3 = buildNeighbourList<3>(plate, 2.1 * dx);
  const NeighbourList nb2 = buildNeighbourList<2>(square, 2.1 * dx);
  for (int parts : {2, 3, 4, 7}) {
    SCOPED_TRACE(std::to_string(parts) + " parts");
    std::vector<DomainPartition> all = {partitionByBisection<3>(plate, nb3, parts),
                                        partitionByBisection<2>(square, nb2, parts)};
    if (haveMetis()) {
      all.push_back(partitionByMetis(nb3, parts));
      all.push_back(partitionByMetis(nb2, parts));
    }
    for (std::size_t k = 0; k < all.size(); ++k) {
      const NeighbourList& nb = k % 2 == 0 ? nb3 : nb2;
      expectConsistent(all[k], nb);
      // Bisection balances to a particle's weight; METIS to its default 3 %.
      EXPECT_LT(all[k].imbalance(nb), 1.035) << all[k].method;
    }
    if (haveMetis())
      std::cout << parts << " parts, 40 x 40 x 4 plate: halo bisection " << all[0].haloTotal()
                << ", METIS " << all[2].haloTotal() << "; 60 x 45 square: bisection "
                << all[1].haloTotal() << ", METIS " << all[3].haloTotal() << "\n";
  }
}

TEST(DomainPartition, KeepsTheSmallerHaloAndIsReproducible) {
  const double dx = 0.01;
  const auto X = cellCentredLattice<3>(Vec<3>::Zero(), {30, 20, 6}, dx);
  const NeighbourList nb = buildNeighbourList<3>(X, 2.1 * dx);
  for (int parts : {1, 2, 4}) {
    const DomainPartition chosen = partitionParticles<3>(X, nb, parts);
    expectConsistent(chosen, nb);
    EXPECT_LE(chosen.haloTotal(), partitionByBisection<3>(X, nb, parts).haloTotal());
    if (haveMetis()) {
      EXPECT_LE(chosen.haloTotal(), partitionByMetis(nb, parts).haloTotal());
    }
    EXPECT_EQ(chosen.part, partitionParticles<3>(X, nb, parts).part);
    if (parts == 1) {
      EXPECT_EQ(chosen.haloTotal(), 0);
    }
  }
}

TEST(DomainPartition, KeepTogetherPutsEveryChainOfLinksInOnePart) {
  // A 2D strip cut in two across its length; links that straddle the cut (as a clamp's ghost and
  // the particles it follows may) and a chain through three particles.
  const double dx = 0.01;
  const auto X = cellCentredLattice<2>(Vec<2>::Zero(), {40, 6}, dx);
  const NeighbourList nb = buildNeighbourList<2>(X, 2.1 * dx);
  DomainPartition p = partitionByBisection<2>(X, nb, 2);
  auto at = [&](int column, int row) {
    const Vec<2> point((column + 0.5) * dx, (row + 0.5) * dx);
    for (Index i = 0; i < static_cast<Index>(X.size()); ++i)
      if ((X[i] - point).norm() < 1e-9) return i;
    return Index(-1);
  };
  const Index a = at(19, 2), b = at(20, 2), c = at(25, 4), first = at(0, 0), last = at(39, 5);
  ASSERT_NE(p.part[a], p.part[b]);
  const std::vector<std::pair<Index, Index>> links = {{c, b}, {b, a}};
  const int chainPart = p.part[std::min({a, b, c})];  // the chain's lowest index decides
  const int firstPart = p.part[first], lastPart = p.part[last];
  keepTogether(p, links, nb);
  expectConsistent(p, nb);
  EXPECT_EQ(p.part[a], chainPart);
  EXPECT_EQ(p.part[b], chainPart);
  EXPECT_EQ(p.part[c], chainPart);
  EXPECT_EQ(p.part[first], firstPart);  // the others stay where they were
  EXPECT_EQ(p.part[last], lastPart);
}

}  // namespace
