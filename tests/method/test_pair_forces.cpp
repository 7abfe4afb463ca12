// The composed plain evaluation (method/PairForces.hpp): with every conservative term on
// (quadratic correction, Taylor term, energy penalty) the force is -d(E + E_q + E_hg)/du;
// with every term on (the textbook penalty, viscosity) it still conserves linear and angular
// momentum; the exposed textbook and viscous parts are exactly what they add; with no
// auxiliary term it is the internal force (6.70) alone.
#include <gtest/gtest.h>

#include "PlainEvaluator.hpp"

using namespace tlsph;
using namespace tlsph::testing;

namespace {

constexpr double kDx = 0.01;

template <int D>
Scene<D> blockScene(std::mt19937& rng, double alpha, HourglassForm form, Quadrature quadrature) {
  std::array<int, D> counts;
  counts.fill(D == 2 ? 7 : 4);
  auto scene = sceneOf<D>(perturbedBlock<D>(counts, kDx, 0.2, rng), kDx, 2.4,
                          testMaterial("neo-hookean"), alpha, form);
  scene.gradientCorrection = GradientCorrection::Quadratic;
  scene.quadrature = quadrature;
  return scene;
}

template <int D>
std::vector<Vec<D>> deformation(const std::vector<Vec<D>>& X, std::mt19937& rng) {
  // affine, bent (curvature up to 2/m) and noisy
  const Mat<D> A = randomMatrix<D>(rng, 0.1);
  const Vec<D> bend = randomVector<D>(rng, 0.01);
  std::vector<Vec<D>> u(X.size());
  for (std::size_t i = 0; i < X.size(); ++i)
    u[i] = A * X[i] + X[i].squaredNorm() / kDx * bend + randomVector<D>(rng, 0.02 * kDx);
  return u;
}

template <int D>
void expectConservativeCompositionIsMinusEnergyGradient(std::uint32_t seed) {
  std::mt19937 rng(seed);
  PlainEvaluator<D> eval(blockScene<D>(rng, 10.0, HourglassForm::Energy, Quadrature::Taylor));
  double fmax = 0.0;
  const double worst =
      energyGradientError<D>(eval, deformation<D>(eval.X(), rng), 1e-6 * kDx, fmax);
  ASSERT_GT(fmax, 0.0);
  EXPECT_LT(worst, 1e-6 * fmax) << D << "D";
}

template <int D>
void expectEveryTermConservesMomentum(std::uint32_t seed) {
  std::mt19937 rng(seed);
  auto scene = blockScene<D>(rng, 10.0, HourglassForm::Ganzenmueller, Quadrature::Taylor);
  scene.viscosity = {1.0, 2.0};
  PlainEvaluator<D> eval(std::move(scene));
  const auto u = deformation<D>(eval.X(), rng);
  std::vector<Vec<D>> v(eval.size());
  for (auto& vi : v)
    vi = randomVector<D>(rng, 1.0);
  const auto f = eval.force(u, &v);
  const auto x = eval.currentPositions(u);
  Vec<D> total = Vec<D>::Zero();
  double scale = 0.0, armScale = 0.0;
  for (Index i = 0; i < eval.size(); ++i) {
    total += f[i];
    scale += f[i].norm();
    armScale += x[i].norm() * f[i].norm();
  }
  EXPECT_LT(total.norm(), 1e-13 * scale);
  EXPECT_LT(torque<D>(x, f).norm(), 1e-12 * armScale);

  // the exposed parts: the force without them is that of the same scene without the terms
  Scene<D> bare = eval.scene();
  bare.hourglassCoefficient = 0.0;
  bare.viscosity = {};
  PlainEvaluator<D> internal(std::move(bare));
  const auto f0 = internal.force(u);
  const auto& hourglass = eval.forces().hourglassForce();
  const auto& viscous = eval.forces().viscousForce();
  double worst = 0.0, largestHourglass = 0.0, largestViscous = 0.0;
  for (Index i = 0; i < eval.size(); ++i) {
    worst = std::max(worst, (f[i] - f0[i] - hourglass[i] - viscous[i]).norm());
    largestHourglass = std::max(largestHourglass, hourglass[i].norm());
    largestViscous = std::max(largestViscous, viscous[i].norm());
  }
  EXPECT_GT(largestHourglass, 0.0);
  EXPECT_GT(largestViscous, 0.0);
  EXPECT_LT(worst, 1e-12 * scale);
}

}  // namespace

TEST(PairForces, ConservativeCompositionIsMinusEnergyGradient) {
  expectConservativeCompositionIsMinusEnergyGradient<2>(91);
  expectConservativeCompositionIsMinusEnergyGradient<3>(92);
}

TEST(PairForces, EveryTermConservesMomentum) {
  expectEveryTermConservesMomentum<2>(93);
  expectEveryTermConservesMomentum<3>(94);
}

TEST(PairForces, WithoutAuxiliaryTermsItIsTheInternalForce) {
  std::mt19937 rng(95);
  PlainEvaluator<2> eval(blockScene<2>(rng, 0.0, HourglassForm::Energy, Quadrature::Nodal));
  const auto u = deformation<2>(eval.X(), rng);
  const auto f = eval.force(u);
  const auto& scene = eval.scene();
  const auto F = deformationGradients<2>(eval.reference(), u);
  const auto P = firstPiolaKirchhoffStresses<2>(scene.materials, scene.particles.material, F);
  const auto expected = internalForce<2>(eval.reference(), scene.particles.volume, P);
  ASSERT_EQ(f.size(), expected.size());
  for (std::size_t i = 0; i < f.size(); ++i)
    EXPECT_EQ(f[i], expected[i]) << i;
  EXPECT_FALSE(eval.forces().hourglassEnabled());
  EXPECT_FALSE(eval.forces().viscosityEnabled());
  EXPECT_EQ(eval.forces().quadrature(), nullptr);
  EXPECT_EQ(eval.forces().hourglassEnergy(u), 0.0);
}
