// What observers read after a force pass (TlsphForces::observe). In 3D with the energy
// penalty on the corrected F the step keeps F only in the penalty's padded copy, and with the
// Taylor quadrature it does not keep grad grad u; observers get both filled in on their first
// read after a compute(). What they read must be the last compute()'s state, bit for bit,
// whether or not the state before it was read (a stale copy is the failure this guards), and
// the same as where the step stores it itself (penalty off, or 2D). And, with passive particles
// (mirrored ghosts), no stress of one step may be left over into the next.
#include <gtest/gtest.h>

#include "TestSupport.hpp"

using namespace tlsph;
using namespace tlsph::testing;

namespace {

constexpr double kDx = 0.01;

struct Case {
  double alpha;
  Quadrature quadrature;
  HourglassGradient penaltyGradient;
};

template <int D>
Scene<D> sceneFor(const Case& c, const std::vector<Vec<D>>& X) {
  Scene<D> scene = sceneOf<D>(X, kDx, 2.4, testMaterial("neo-hookean"), c.alpha);
  scene.gradientCorrection = GradientCorrection::Quadratic;
  scene.quadrature = c.quadrature;
  scene.hourglassGradient = c.penaltyGradient;
  return scene;
}

template <int D>
std::unique_ptr<ForceEvaluator<D>> evaluatorFor(const Case& c, const std::vector<Vec<D>>& X) {
  return std::make_unique<ForceEvaluator<D>>(sceneFor<D>(c, X));
}

// A smooth non-affine displacement (grad grad u != 0) of size `size`.
template <int D>
std::vector<Vec<D>> displacement(const std::vector<Vec<D>>& X, double size, std::mt19937& rng) {
  const Mat<D> A = randomMatrix<D>(rng, size);
  const Vec<D> b = randomVector<D>(rng, size);
  std::vector<Vec<D>> u(X.size());
  for (std::size_t i = 0; i < X.size(); ++i)
    u[i] = A * X[i] + X[i].squaredNorm() / kDx * b;
  return u;
}

// A jittered block and two displacements of it.
template <int D>
struct Block {
  std::vector<Vec<D>> X, u1, u2;
};
template <int D>
Block<D> blockFor(std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::array<int, D> counts;
  counts.fill(D == 2 ? 6 : 4);
  counts[0] = D == 2 ? 8 : 5;
  Block<D> b;
  b.X = perturbedBlock<D>(counts, kDx, 0.15, rng);
  b.u1 = displacement<D>(b.X, 1e-3, rng);
  b.u2 = displacement<D>(b.X, 2e-3, rng);
  return b;
}

template <int D>
std::string traceOf(const Case& c) {
  return "D=" + std::to_string(D) + " alpha " + std::to_string(c.alpha) +
         (c.quadrature == Quadrature::Taylor ? " taylor" : " nodal") +
         (c.penaltyGradient == HourglassGradient::Linear ? " penalty on the linear F" : "");
}

template <int D>
void expectObserversReadTheLastCompute(const Case& c, std::uint32_t seed) {
  const auto [X, u1, u2] = blockFor<D>(seed);
  SCOPED_TRACE(traceOf<D>(c));

  // read after the first compute, then computed again
  auto read = evaluatorFor<D>(c, X);
  read->force(u1);
  const std::vector<Mat<D>> F1(read->forces().deformationGradient().begin(),
                               read->forces().deformationGradient().end());
  const double E1 = read->forces().strainEnergy();
  const auto f2 = read->force(u2);
  // computed twice, read once
  auto unread = evaluatorFor<D>(c, X);
  unread->force(u1);
  const auto f2unread = unread->force(u2);
  // the same scene without the penalty: the step keeps F itself
  Case off = c;
  off.alpha = 0.0;
  auto plain = evaluatorFor<D>(off, X);
  plain->force(u2);

  const Index n = read->size();
  const auto& F = read->forces().deformationGradient();
  const auto& Funread = unread->forces().deformationGradient();
  const auto& Fplain = plain->forces().deformationGradient();
  double moved = 0.0;
  for (Index i = 0; i < n; ++i) {
    ASSERT_EQ(F[i], Funread[i]) << "particle " << i;
    ASSERT_EQ(F[i], Fplain[i]) << "particle " << i;
    ASSERT_EQ(f2[i], f2unread[i]) << "particle " << i;
    moved = std::max(moved, (F[i] - F1[i]).cwiseAbs().maxCoeff());
  }
  EXPECT_GT(moved, 1e-4);  // u2 moved F: a stale copy would fail the checks above
  const double E2 = read->forces().strainEnergy();
  EXPECT_EQ(E2, unread->forces().strainEnergy());
  EXPECT_EQ(E2, plain->forces().strainEnergy());
  EXPECT_NE(E2, E1);
  EXPECT_EQ(read->forces().hourglassEnergy(u2), unread->forces().hourglassEnergy(u2));

  if (c.quadrature != Quadrature::Taylor) return;
  const auto* q = read->forces().quadrature();
  const auto& G = q->secondGradients();
  const auto& Gunread = unread->forces().quadrature()->secondGradients();
  double scale = 0.0, error = 0.0;
  for (Index i = 0; i < n; ++i) {
    ASSERT_EQ(G[i], Gunread[i]) << "particle " << i;
    // against the plain (unpadded) sums of the same fit at u2: rounding only
    const auto expected = q->secondGradients(i, u2);
    const auto got = TaylorQuadrature<D>::unpack(G[i]);
    for (int a = 0; a < D; ++a) {
      scale = std::max(scale, expected[a].cwiseAbs().maxCoeff());
      error = std::max(error, (got[a] - expected[a]).cwiseAbs().maxCoeff());
    }
  }
  EXPECT_GT(scale, 0.0);
  EXPECT_LT(error, 1e-12 * scale);
}

// With passive particles (mirrored ghosts: an F, no stress) as well: a compute() gives what it
// gives on fresh arrays, nothing of the last step's stresses left in them (with the penalty on
// F, P + P^q is written into the array the penalty adds P^hg to).
template <int D>
void expectNoStressCarriedOver(const Case& c, std::uint32_t seed) {
  const auto [X, u1, u2] = blockFor<D>(seed);
  const Scene<D> scene = sceneFor<D>(c, X);
  const auto& p = scene.particles;
  const auto ref = buildReferenceConfiguration<D>(p.referencePosition, p.volume,
                                                  Kernel<D>(scene.kernel, scene.supportRadius),
                                                  scene.periodicBox, scene.gradientCorrection);
  std::vector<Index> passive;  // the first layer in x
  for (Index i = 0; i < p.size(); ++i)
    if (X[i].x() < kDx) passive.push_back(i);
  ASSERT_FALSE(passive.empty());
  auto forces = [&] {
    return std::make_unique<TlsphForces<D>>(ref, scene.materials, p.material, p.volume,
                                            scene.hourglass(), scene.quadrature,
                                            ViscositySettings{}, 0.0, passive);
  };
  SCOPED_TRACE(traceOf<D>(c));
  std::vector<Vec<D>> f(p.size()), fresh(p.size());
  auto twice = forces();
  twice->compute(u1, f);
  twice->compute(u2, f);
  forces()->compute(u2, fresh);
  for (Index i = 0; i < p.size(); ++i)
    ASSERT_EQ(f[i], fresh[i]) << "particle " << i;
}

const Case kCases[] = {
    {0.0, Quadrature::Nodal, HourglassGradient::Corrected},
    {0.1, Quadrature::Nodal, HourglassGradient::Corrected},
    {0.0, Quadrature::Taylor, HourglassGradient::Corrected},
    {0.1, Quadrature::Taylor, HourglassGradient::Corrected},
    {0.1, Quadrature::Taylor, HourglassGradient::Linear},
};

TEST(ObservedState, ReadsTheLastComputeIn3D) {
  std::uint32_t seed = 11;
  for (const Case& c : kCases)
    expectObserversReadTheLastCompute<3>(c, seed++);
}

TEST(ObservedState, ReadsTheLastComputeIn2D) {
  std::uint32_t seed = 23;
  for (const Case& c : kCases)
    expectObserversReadTheLastCompute<2>(c, seed++);
}

TEST(ObservedState, NoStressCarriedOverWithPassiveParticles) {
  std::uint32_t seed = 37;
  for (const Case& c : kCases) {
    expectNoStressCarriedOver<3>(c, seed++);
    expectNoStressCarriedOver<2>(c, seed++);
  }
}

}  // namespace
