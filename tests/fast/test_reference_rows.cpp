// Pair data for some particles only (buildNeighbourRows, buildReferenceConfiguration's rows:
// a distributed rank keeps the pair data of its own particles and its halo, not the whole
// body's): each built row is bit for bit the whole build's row, the reverse vectors too where
// the neighbour is built, and the forces on a rank's particles, computed from such a build,
// are bit for bit the whole build's (2D and 3D, both corrections, Taylor quadrature, both
// hourglass forms and gradients, artificial viscosity).
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "fast/TlsphForces.hpp"
#include "geometry/Lattice.hpp"

using namespace tlsph;

namespace {

constexpr double kDx = 0.01;

// A communicator of one rank that moves nothing: the test computes everything it reads.
class Alone final : public Communicator {
 public:
  int rank() const override { return 0; }
  int size() const override { return 1; }
  void setPartition(const DomainPartition&, const NeighbourList&) override {}
  void exchangeHaloBytes(char*, std::size_t) override {}
  void gatherAllBytes(char*, std::size_t) override {}
  void sum(double*, int) override {}
  void max(double*, int) override {}
  void broadcastBytes(char*, std::size_t, int) override {}
  void barrier() override {}
};

// The particles of `set` and their neighbours (ascending).
std::vector<Index> withNeighbours(const NeighbourList& nb, const std::vector<Index>& set) {
  std::vector<Index> out = set;
  for (Index i : set)
    out.insert(out.end(), nb.neighbour.begin() + nb.offset[i],
               nb.neighbour.begin() + nb.offset[i + 1]);
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

template <int D>
std::vector<Vec<D>> lattice() {
  if constexpr (D == 2)
    return cellCentredLattice<2>(Vec<2>::Zero(), {24, 10}, kDx);
  else
    return cellCentredLattice<3>(Vec<3>::Zero(), {16, 6, 5}, kDx);
}

// The particles left of a plane across the body: a rank's share.
template <int D>
std::vector<Index> share(const std::vector<Vec<D>>& X, double fraction) {
  double lo = X[0].x(), hi = X[0].x();
  for (const auto& x : X) {
    lo = std::min(lo, x.x());
    hi = std::max(hi, x.x());
  }
  std::vector<Index> s;
  for (Index i = 0; i < static_cast<Index>(X.size()); ++i)
    if (X[i].x() < lo + fraction * (hi - lo)) s.push_back(i);
  return s;
}

template <int D>
void expectRowsAsWhole(GradientCorrection correction, const PeriodicBox<D>& box) {
  const auto X = lattice<D>();
  const std::vector<double> V(X.size(), std::pow(kDx, D));
  const Kernel<D> kernel(KernelType::WendlandC2, 2.1 * kDx);
  const auto whole = buildReferenceConfiguration<D>(X, V, kernel, box, correction);
  const std::vector<Index> own = share<D>(X, 0.4);
  const std::vector<Index> rows = withNeighbours(whole.neighbours, own);
  const auto part = buildReferenceConfiguration<D>(X, V, kernel, box, correction,
                                                   kDefaultMinCorrectionCondition, &rows);
  const auto& a = whole.neighbours;
  const auto& b = part.neighbours;
  ASSERT_EQ(b.particleCount(), a.particleCount());
  std::vector<std::uint8_t> built(X.size(), 0);
  for (Index i : rows)
    built[i] = 1;
  for (Index i = 0; i < a.particleCount(); ++i) {
    if (!built[i]) {
      EXPECT_EQ(b.count(i), 0) << i;
      continue;
    }
    ASSERT_EQ(b.count(i), a.count(i)) << i;
    EXPECT_EQ(part.correctionInverse[i], whole.correctionInverse[i]) << i;
    EXPECT_EQ(part.correctedGradientSum[i], whole.correctedGradientSum[i]) << i;
    for (Index k = 0; k < a.count(i); ++k) {
      const Index ka = a.offset[i] + k, kb = b.offset[i] + k;
      ASSERT_EQ(b.neighbour[kb], a.neighbour[ka]);
      EXPECT_EQ(part.separation[kb], whole.separation[ka]);
      EXPECT_EQ(part.correctedGradient[kb], whole.correctedGradient[ka]);
      if (correction == GradientCorrection::Quadratic) {
        EXPECT_EQ(part.linearGradient[kb], whole.linearGradient[ka]);
      }
      if (built[a.neighbour[ka]]) {
        EXPECT_EQ(part.reverseGradient[kb], whole.reverseGradient[ka]) << i;
      } else {
        EXPECT_EQ(part.reverseGradient[kb], Vec<D>::Zero());
      }
    }
  }
  // Far fewer pairs kept than in the whole build.
  EXPECT_LT(b.pairCount(), a.pairCount() * 7 / 10);
}

TEST(ReferenceRows, BuiltRowsAreTheWholeBuildsRows) {
  expectRowsAsWhole<2>(GradientCorrection::Linear, {});
  expectRowsAsWhole<2>(GradientCorrection::Quadratic, {});
  expectRowsAsWhole<3>(GradientCorrection::Quadratic, {});
  PeriodicBox<2> box;  // across the periodic seam, too
  box.periodic[0] = true;
  box.origin = Vec<2>::Zero();
  box.length = Vec<2>(24 * kDx, 10 * kDx);
  expectRowsAsWhole<2>(GradientCorrection::Quadratic, box);
}

struct ForceCase {
  GradientCorrection correction;
  Quadrature quadrature;
  HourglassSettings hourglass;
  ViscositySettings viscosity;
};

template <int D>
void expectForcesAsWhole(const ForceCase& c) {
  const auto X = lattice<D>();
  const Index n = static_cast<Index>(X.size());
  const std::vector<double> V(n, std::pow(kDx, D));
  const Kernel<D> kernel(KernelType::WendlandC2, 2.1 * kDx);
  const std::vector<Material> materials = {
      makeMaterial("neo-hookean", ElasticConstants::fromYoungPoisson(1e6, 0.3), 1000.0)};
  const std::vector<std::uint16_t> materialOf(n, 0);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> small(-0.02 * kDx, 0.02 * kDx);
  std::vector<Vec<D>> u(n), v(n);
  for (Index i = 0; i < n; ++i)
    for (int a = 0; a < D; ++a) {
      u[i][a] = 0.05 * X[i][a] * X[i][(a + 1) % D] / kDx + small(rng);
      v[i][a] = small(rng) * 100.0;
    }

  const auto whole = buildReferenceConfiguration<D>(X, V, kernel, {}, c.correction);
  TlsphForces<D> all(whole, materials, materialOf, V, c.hourglass, c.quadrature, c.viscosity,
                     1.05 * kDx);
  std::vector<Vec<D>> fAll(n, Vec<D>::Zero());
  all.compute(u, fAll, &v);

  // This "rank" computes S and two layers around it (what the forces on S read: neighbours'
  // stresses, which read their neighbours' F), with pair data for one layer more.
  const std::vector<Index> S = share<D>(X, 0.3);
  const std::vector<Index> owned =
      withNeighbours(whole.neighbours, withNeighbours(whole.neighbours, S));
  const std::vector<Index> rows = withNeighbours(whole.neighbours, owned);
  const auto part = buildReferenceConfiguration<D>(X, V, kernel, {}, c.correction,
                                                   kDefaultMinCorrectionCondition, &rows);
  TlsphForces<D> mine(part, materials, materialOf, V, c.hourglass, c.quadrature, c.viscosity,
                      1.05 * kDx);
  Alone alone;
  mine.distribute(owned, &alone);
  std::vector<Vec<D>> fMine(n, Vec<D>::Zero());
  mine.compute(u, fMine, &v);
  for (Index i : S)
    ASSERT_EQ(fMine[i], fAll[i]) << "particle " << i;
  EXPECT_LT(part.neighbours.pairCount(), whole.neighbours.pairCount());
}

TEST(ReferenceRows, ForcesOnARanksParticlesAreTheWholeBuilds) {
  HourglassSettings energy{10.0, HourglassForm::Energy, HourglassGradient::Corrected};
  HourglassSettings linearF{10.0, HourglassForm::Energy, HourglassGradient::Linear};
  HourglassSettings textbook{2.0, HourglassForm::Ganzenmueller, HourglassGradient::Corrected};
  const ViscositySettings none{}, viscous{0.5, 1.0};
  for (const ForceCase& c :
       {ForceCase{GradientCorrection::Quadratic, Quadrature::Taylor, energy, none},
        ForceCase{GradientCorrection::Quadratic, Quadrature::Taylor, linearF, viscous},
        ForceCase{GradientCorrection::Quadratic, Quadrature::Nodal, energy, none},
        ForceCase{GradientCorrection::Linear, Quadrature::Nodal, textbook, viscous}}) {
    SCOPED_TRACE(std::string(quadratureName(c.quadrature)) + ", " +
                 hourglassFormName(c.hourglass.form));
    expectForcesAsWhole<2>(c);
    expectForcesAsWhole<3>(c);
  }
}

}  // namespace
