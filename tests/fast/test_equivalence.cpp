// The fast force passes (TlsphForces: fused, padded, prefetched, two particles at a time, the
// internal force summed from its sources when it is the only pair term, threaded) against the
// plain reference evaluation (method/PairForces.hpp), for every combination of terms a scene
// can ask for, on a jittered 2D and 3D block of two materials with a mirrored ghost layer:
// F to 1e-13, the force to 1e-12 of its largest value, the energies to 1e-12.
// The combinations reach every fast path: the internal force summed from its sources
// (InternalForceScatter, 512-bit interleaved records where compiled) when it is the only pair
// term or carries the energy penalty on the same F, gathered otherwise; in 3D the two-particle
// padded sums of the F pass (the Taylor fit's, and the nodal one when the penalty reads F);
// the penalty's own linear F beside the quadratic one; passive particles in their own group.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "TestSupport.hpp"
#include "fast/TlsphForces.hpp"
#include "method/PairForces.hpp"

using namespace tlsph;
using namespace tlsph::testing;

namespace {

constexpr double kDx = 0.01;
constexpr double kSupportRatio = 2.4;

// The body: a jittered block above the plane y = 0, two materials side by side (one of them
// linear-elastic, whose Taylor term has no P^q). With ghosts: the body's particles within the
// support of the plane mirrored below it, passive, moved as the mirror image of their own.
template <int D>
struct Body {
  std::vector<Vec<D>> X;
  std::vector<double> volume;
  std::vector<std::uint16_t> material;
  std::vector<Index> passive;
  std::vector<Index> original;  // the body particle a particle is (or mirrors)
  std::vector<Material> materials{testMaterial("neo-hookean"), testMaterial("linear-elastic")};

  Body(std::uint32_t seed, bool ghosts) {
    std::mt19937 rng(seed);
    std::array<int, D> counts;
    counts.fill(D == 2 ? 8 : 5);
    counts[0] = D == 2 ? 9 : 6;
    // jittered by up to 0.15 dx: every quadratic fit stays well conditioned. (Where a fit's
    // moment matrix is nearly singular, the two sides' inverses, compiled in different units,
    // differ by its condition number times the rounding, which no 1e-12 bound holds.)
    X = perturbedBlock<D>(counts, kDx, 0.15, rng);
    const Index body = static_cast<Index>(X.size());
    for (Index i = 0; i < body; ++i) {
      original.push_back(i);
      material.push_back(X[i][0] < 0.5 * counts[0] * kDx ? 0 : 1);
    }
    if (ghosts)
      for (Index i = 0; i < body; ++i)
        if (X[i][1] < kSupportRatio * kDx) {
          Vec<D> mirrored = X[i];
          mirrored[1] = -mirrored[1];
          passive.push_back(static_cast<Index>(X.size()));
          X.push_back(mirrored);
          original.push_back(i);
          material.push_back(material[i]);
        }
    volume.assign(X.size(), std::pow(kDx, D));
  }

  // A smooth field (affine plus quadratic) with particle noise, mirrored on the ghosts.
  std::vector<Vec<D>> field(std::mt19937& rng, double affine, double curvature,
                            double noise) const {
    const Mat<D> A = randomMatrix<D>(rng, affine);
    std::array<Mat<D>, D> B;
    for (auto& b : B)
      b = randomMatrix<D>(rng, curvature);
    std::vector<Vec<D>> w(X.size());
    for (std::size_t i = 0; i < X.size(); ++i) {
      const Vec<D>& Xo = X[original[i]];
      if (original[i] == static_cast<Index>(i)) {
        w[i] = A * Xo + randomVector<D>(rng, noise);
        for (int a = 0; a < D; ++a)
          w[i][a] += Xo.dot(B[a] * Xo);
      } else {
        w[i] = w[original[i]];
        w[i][1] = -w[i][1];
      }
    }
    return w;
  }
};

struct Terms {
  GradientCorrection correction;
  Quadrature quadrature;
  HourglassSettings hourglass;
  bool viscous;
  bool ghosts;
  std::string name() const {
    std::string s = gradientCorrectionName(correction);
    s += std::string(" ") + quadratureName(quadrature);
    if (!hourglass.enabled())
      s += " no penalty";
    else
      s += std::string(" ") + hourglassFormName(hourglass.form) + " penalty on the " +
           hourglassGradientName(hourglass.gradient) + " F";
    s += viscous ? " viscous" : "";
    s += ghosts ? " ghosts" : "";
    return s;
  }
};

double largestNorm(const auto& values) {
  double m = 0.0;
  for (const auto& v : values)
    m = std::max(m, v.norm());
  return m;
}

double largestDifference(const auto& a, const auto& b) {
  double m = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i)
    m = std::max(m, (a[i] - b[i]).cwiseAbs().maxCoeff());
  return m;
}

template <int D>
void expectEquivalent(const Terms& terms, std::uint32_t seed) {
  SCOPED_TRACE(std::to_string(D) + "D, " + terms.name());
  const Body<D> body(seed, terms.ghosts);
  const double H = kSupportRatio * kDx;
  const auto ref = buildReferenceConfiguration<D>(
      body.X, body.volume, Kernel<D>(KernelType::WendlandC2, H), {}, terms.correction);
  ViscositySettings viscosity;
  if (terms.viscous) viscosity = {1.0, 2.0};
  std::mt19937 rng(seed + 1000);
  const auto u = body.field(rng, 0.05, 2.0, 0.02 * kDx);
  const auto v = body.field(rng, 20.0, 200.0, 0.5);  // m/s: pairs approach and separate

  PairForces<D> plain(ref, body.materials, body.material, body.volume, terms.hourglass,
                      terms.quadrature, viscosity, 0.5 * H, body.passive);
  std::vector<Vec<D>> fPlain;
  plain.compute(u, fPlain, &v);
  const double fScale = largestNorm(fPlain);
  ASSERT_GT(fScale, 0.0);
  const double E = plain.strainEnergy(), Ehg = plain.hourglassEnergy(u);
  ASSERT_GT(E, 0.0);

#ifdef _OPENMP
  const int threadCounts[] = {1, 2, 3};
#else
  const int threadCounts[] = {1};
#endif
  for (int threads : threadCounts) {
    SCOPED_TRACE(std::to_string(threads) + " threads");
#ifdef _OPENMP
    omp_set_num_threads(threads);
#endif
    TlsphForces<D> fast(ref, body.materials, body.material, body.volume, terms.hourglass,
                        terms.quadrature, viscosity, 0.5 * H, body.passive);
    std::vector<Vec<D>> f(body.X.size());
    fast.compute(u, f, &v);
    EXPECT_LT(largestDifference(fast.deformationGradient(), plain.deformationGradient()), 1e-13);
    EXPECT_LT(largestDifference(f, fPlain), 1e-12 * fScale);
    EXPECT_NEAR(fast.strainEnergy(), E, 1e-12 * E);
    EXPECT_NEAR(fast.hourglassEnergy(u), Ehg, 1e-12 * Ehg);
    if (terms.hourglass.enabled() && terms.hourglass.form == HourglassForm::Energy) {
      EXPECT_GT(Ehg, 0.0);
    }
    ASSERT_EQ(fast.hourglassForce().size(), plain.hourglassForce().size());
    EXPECT_LE(largestDifference(fast.hourglassForce(), plain.hourglassForce()),
              1e-12 * largestNorm(plain.hourglassForce()));
    ASSERT_EQ(fast.viscousForce().size(), plain.viscousForce().size());
    EXPECT_LE(largestDifference(fast.viscousForce(), plain.viscousForce()),
              1e-12 * largestNorm(plain.viscousForce()));
    if (terms.viscous) {
      EXPECT_GT(largestNorm(plain.viscousForce()), 0.0);
    }
    ASSERT_EQ(fast.quadrature() != nullptr, plain.quadrature() != nullptr);
    if (plain.quadrature()) {
      double scale = 0.0, error = 0.0;
      for (std::size_t i = 0; i < body.X.size(); ++i) {
        if (std::ranges::count(body.passive, Index(i))) continue;  // no term, none kept
        const auto G = TaylorQuadrature<D>::unpack(fast.quadrature()->secondGradients()[i]);
        for (int a = 0; a < D; ++a) {
          scale = std::max(scale, plain.secondGradients()[i][a].cwiseAbs().maxCoeff());
          error = std::max(error, (G[a] - plain.secondGradients()[i][a]).cwiseAbs().maxCoeff());
        }
      }
      EXPECT_GT(scale, 0.0);
      // the two fits' inverses round differently (the force sums them back to 1e-12)
      EXPECT_LT(error, 1e-10 * scale);
    }
  }
#ifdef _OPENMP
  omp_set_num_threads(1);
#endif
}

// Every penalty a scene accepts: off, the energy form on the corrected and on the linear F,
// the textbook form (always on the linear F); each with and without viscosity and ghosts.
template <int D>
void expectEquivalentForEveryTerm(GradientCorrection correction, Quadrature quadrature,
                                  std::uint32_t seed) {
  const HourglassSettings penalties[] = {
      {0.0, HourglassForm::Energy, HourglassGradient::Corrected},
      {10.0, HourglassForm::Energy, HourglassGradient::Corrected},
      {10.0, HourglassForm::Energy, HourglassGradient::Linear},
      {10.0, HourglassForm::Ganzenmueller, HourglassGradient::Corrected}};
  for (const auto& hourglass : penalties)
    for (bool viscous : {false, true})
      for (bool ghosts : {false, true})
        expectEquivalent<D>({correction, quadrature, hourglass, viscous, ghosts}, seed++);
}

const auto kLinear = GradientCorrection::Linear;
const auto kQuadratic = GradientCorrection::Quadratic;

}  // namespace

TEST(Equivalence, LinearNodal2D) {
  expectEquivalentForEveryTerm<2>(kLinear, Quadrature::Nodal, 1);
}
TEST(Equivalence, LinearNodal3D) {
  expectEquivalentForEveryTerm<3>(kLinear, Quadrature::Nodal, 101);
}
TEST(Equivalence, QuadraticNodal2D) {
  expectEquivalentForEveryTerm<2>(kQuadratic, Quadrature::Nodal, 201);
}
TEST(Equivalence, QuadraticNodal3D) {
  expectEquivalentForEveryTerm<3>(kQuadratic, Quadrature::Nodal, 301);
}
TEST(Equivalence, QuadraticTaylor2D) {
  expectEquivalentForEveryTerm<2>(kQuadratic, Quadrature::Taylor, 401);
}
TEST(Equivalence, QuadraticTaylor3D) {
  expectEquivalentForEveryTerm<3>(kQuadratic, Quadrature::Taylor, 501);
}
