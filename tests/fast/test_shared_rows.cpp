// Per-pair rows stored once per distinct row (SharedRows.hpp): every particle reads
// back exactly its own row, rows are shared only when equal bit for bit, and the operators that
// keep their per-pair data this way (the Taylor fit and its reverse) still hold the relations
// the force's exactness rests on (g_IJ of the fit = the corrected gradient vectors,
// T_IJ = (V_J / V_I) S_JI, bit for bit). streams(): whether a pass over the particles in order
// reads the rows front to back, where the pair loops prefetch ahead.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <random>
#include <vector>

#include "TestSupport.hpp"
#include "fast/SharedRows.hpp"
#include "fast/TaylorQuadrature.hpp"
#include "method/ReferenceConfiguration.hpp"

using namespace tlsph;
using namespace tlsph::testing;

namespace {

NeighbourList listOfCounts(const std::vector<Index>& counts) {
  NeighbourList nb;
  nb.offset.push_back(0);
  for (Index c : counts) {
    for (Index m = 0; m < c; ++m)
      nb.neighbour.push_back(m);
    nb.offset.push_back(nb.offset.back() + c);
  }
  return nb;
}

template <class T>
bool bitwiseEqual(const T& a, const T& b) {
  return std::memcmp(&a, &b, sizeof(T)) == 0;
}

// Every particle's row read through the shared storage is its row of the full array.
template <class T>
void expectRowsReadBack(const NeighbourList& nb, const PairArray<T>& full,
                        const SharedRows<T>& rows) {
  for (Index i = 0; i < nb.particleCount(); ++i) {
    const T* row = rows.row(i);
    for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k)
      ASSERT_TRUE(bitwiseEqual(row[k - nb.offset[i]], full[k]))
          << "particle " << i << " pair " << k;
  }
}

}  // namespace

TEST(SharedRows, SharesOnlyRowsEqualBitForBit) {
  // Rows: 0 = (1, 0, 2), 1 = (1, 0, 2.0000000000000004), 2 = row 0, 3 = (1, -0, 2),
  // 4 = (1, 0) (a prefix of row 0), 5 = row 0.
  const NeighbourList nb = listOfCounts({3, 3, 3, 3, 2, 3});
  const PairArray<double> full{1.0, 0.0, 2.0, 1.0, 0.0,  std::nextafter(2.0, 3.0),
                               1.0, 0.0, 2.0, 1.0, -0.0, 2.0,
                               1.0, 0.0, 1.0, 0.0, 2.0};
  ASSERT_EQ(full.size(), std::size_t(nb.pairCount()));
  const SharedRows<double> rows(nb, PairArray<double>(full));  // handed over: shared if any repeats
  EXPECT_FALSE(rows.aliases());
  EXPECT_EQ(rows.distinctRows(), 4u);   // 0 (= 2 = 5), 1, 3, 4
  EXPECT_EQ(rows.storedValues(), 11u);  // 3 + 3 + 3 + 2
  EXPECT_EQ(rows.row(0), rows.row(2));
  EXPECT_EQ(rows.row(0), rows.row(5));
  EXPECT_NE(rows.row(0), rows.row(1));
  EXPECT_NE(rows.row(0), rows.row(3));  // -0.0 is not merged with 0.0
  EXPECT_NE(rows.row(0), rows.row(4));
  expectRowsReadBack(nb, full, rows);
  // read in particle order the rows jump back three times in five (to row 0, past row 0 to
  // row 3, to row 0): not a forward stream, no prefetch
  EXPECT_FALSE(rows.streams());
}

TEST(SharedRows, EmptyListsAndVectorValues) {
  const NeighbourList nb = listOfCounts({0, 2, 0, 2});
  const PairArray<Vec3> full{Vec3(1, 2, 3), Vec3(4, 5, 6), Vec3(1, 2, 3), Vec3(4, 5, 6)};
  const SharedRows<Vec3> rows(nb, full);  // half the values: kept as a copy
  EXPECT_FALSE(rows.aliases());
  EXPECT_EQ(rows.distinctRows(), 2u);  // the empty row and (a, b)
  EXPECT_EQ(rows.storedValues(), 2u);
  EXPECT_EQ(rows.row(1), rows.row(3));
  expectRowsReadBack(nb, full, rows);
}

// An array that stays (the reference configuration's) is copied only when sharing at least
// halves it, else read in place; an array handed over is kept whole when no row repeats.
TEST(SharedRows, CopiesOnlyWhenItPays) {
  const NeighbourList nb = listOfCounts({2, 2, 2});
  const PairArray<double> twoOfThree{1.0, 2.0, 1.0, 2.0, 3.0, 4.0};
  const SharedRows<double> inPlace(nb, twoOfThree);
  EXPECT_TRUE(inPlace.aliases());
  EXPECT_EQ(inPlace.distinctRows(), 2u);
  EXPECT_EQ(inPlace.storedValues(), 6u);  // what the loops read
  for (Index i = 0; i < 3; ++i)
    EXPECT_EQ(inPlace.row(i), twoOfThree.data() + nb.offset[i]);
  EXPECT_TRUE(inPlace.streams());  // every row where the previous one ended
  const SharedRows<double> handedOver(nb, PairArray<double>(twoOfThree));
  EXPECT_FALSE(handedOver.aliases());
  EXPECT_EQ(handedOver.storedValues(), 4u);
  expectRowsReadBack(nb, twoOfThree, handedOver);
  EXPECT_TRUE(handedOver.streams());  // one step of two forward (row 2 after row 1): half
  const PairArray<double> distinct{1.0, 2.0, 3.0, 4.0, 5.0, 6.0};
  const SharedRows<double> whole(nb, PairArray<double>(distinct));
  EXPECT_FALSE(whole.aliases());
  EXPECT_EQ(whole.distinctRows(), 3u);
  EXPECT_EQ(whole.storedValues(), 6u);
  expectRowsReadBack(nb, distinct, whole);
  EXPECT_TRUE(whole.streams());
}

// On a lattice, whose coordinates are exact on one binary grid (LatticeGrid.hpp) whatever dx and
// the origin, every particle with the same neighbourhood has the same rows to the last bit: they
// are stored once, and every particle still reads its own.
TEST(SharedRows, LatticeRowsAreSharedAndReadBack) {
  const double dx = 0.01;
  const auto X = cellCentredLattice<3>(Vec3(0.0031, -0.05, -0.0047), {20, 8, 8}, dx);
  const std::vector<double> volume(X.size(), dx * dx * dx);
  const auto ref = buildReferenceConfiguration<3>(
      X, volume, Kernel<3>(KernelType::WendlandC2, 2.1 * dx), {}, GradientCorrection::Quadratic);
  const auto& nb = ref.neighbours;
  const SharedRows<Vec3> g(nb, ref.correctedGradient), t(nb, ref.reverseGradient);
  std::cout << "distinct rows of " << nb.particleCount() << " particles: g " << g.distinctRows()
            << ", t " << t.distinctRows() << "\n";
  EXPECT_LT(2 * g.distinctRows(), std::size_t(nb.particleCount()));
  EXPECT_LT(2 * t.distinctRows(), std::size_t(nb.particleCount()));
  EXPECT_FALSE(g.aliases());
  expectRowsReadBack(nb, ref.correctedGradient, g);
  expectRowsReadBack(nb, ref.reverseGradient, t);
  // most particles read a row read before: the pair loops leave out the line-ahead prefetch
  EXPECT_FALSE(g.streams());
  EXPECT_FALSE(t.streams());
}

// The same block moved off the lattice by a millionth of dx: no two rows are equal, each
// particle's row follows the previous one's and the loops prefetch ahead; the rows read back.
TEST(SharedRows, RowsOffTheLatticeStreamForward) {
  const double dx = 0.01;
  std::mt19937 rng(7);
  const auto X = perturbedBlock<3>({20, 8, 8}, dx, 1e-6, rng);
  const std::vector<double> volume(X.size(), dx * dx * dx);
  const auto ref = buildReferenceConfiguration<3>(
      X, volume, Kernel<3>(KernelType::WendlandC2, 2.1 * dx), {}, GradientCorrection::Quadratic);
  const auto& nb = ref.neighbours;
  const SharedRows<Vec3> g(nb, ref.correctedGradient);
  EXPECT_EQ(g.distinctRows(), std::size_t(nb.particleCount()));
  EXPECT_TRUE(g.aliases());
  EXPECT_TRUE(g.streams());
  expectRowsReadBack(nb, ref.correctedGradient, g);
  const SharedRows<Vec3> handedOver(nb, PairArray<Vec3>(ref.correctedGradient));
  EXPECT_TRUE(handedOver.streams());
}

// The Taylor quadrature keeps its fit and its reverse as shared rows: the fit's g_IJ part is
// the reference's corrected gradient and T_IJ = (V_J / V_I) S_JI, bit for bit, through the
// shared storage (the force's momentum balance needs the reverse to be exactly the fit's).
TEST(SharedRows, TaylorFitAndReverseKeepTheirRelations) {
  const double dx = 0.01;
  auto X = cellCentredLattice<3>(Vec3::Zero(), {12, 6, 6}, dx);
  std::vector<double> volume(X.size(), dx * dx * dx);
  for (std::size_t i = 0; i < X.size(); i += 7)
    volume[i] *= 1.1;  // unequal volumes: V_J / V_I matters
  const auto ref = buildReferenceConfiguration<3>(
      X, volume, Kernel<3>(KernelType::WendlandC2, 2.1 * dx), {}, GradientCorrection::Quadratic);
  const std::vector<Material> materials{testMaterial("neo-hookean")};
  const std::vector<std::uint16_t> materialOf(X.size(), 0);
  const TaylorQuadrature<3> q(ref, materials, materialOf, volume, {});
  const auto& nb = ref.neighbours;
  using Q = TaylorQuadrature<3>;
  Index checked = 0;
  for (Index i = 0; i < nb.particleCount(); ++i)
    for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k) {
      const Q::Fit& fit = q.fitRows().row(i)[k - nb.offset[i]];
      const Vec3 g = fit.head<3>().transpose();
      ASSERT_TRUE(bitwiseEqual(g, ref.correctedGradient[k])) << "pair " << k;
      const Index j = nb.neighbour[k];
      const auto first = nb.neighbour.begin() + nb.offset[j];
      const Index m =
          Index(std::lower_bound(first, nb.neighbour.begin() + nb.offset[j + 1], i) - first);
      const Q::Sym Sji = q.fitRows().row(j)[m].tail<Q::P>().transpose();
      const Q::Sym expected = (volume[j] / volume[i]) * Sji;
      ASSERT_TRUE(bitwiseEqual(q.reverseRows().row(i)[k - nb.offset[i]], expected)) << "pair " << k;
      ++checked;
    }
  EXPECT_EQ(checked, nb.pairCount());
}
