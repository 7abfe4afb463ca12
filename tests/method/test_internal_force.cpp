// The internal force is minus the gradient of the discrete strain energy E = sum V_I psi(F_I)
// (which pins the sign of (6.70) and the transpose of L), and it conserves linear momentum.
// With the energy-form hourglass penalty, the force is minus the gradient of E + E_hg.
#include <gtest/gtest.h>

#include "TestSupport.hpp"

using namespace tlsph;
using namespace tlsph::testing;

namespace {

// A random smooth-ish deformation: finite affine part plus particle-wise noise.
template <int D>
std::vector<Vec<D>> randomDeformation(const ForceEvaluator<D>& eval, double dx, std::mt19937& rng) {
  const Mat<D> A = randomMatrix<D>(rng, 0.08);
  std::vector<Vec<D>> u(eval.size());
  for (Index i = 0; i < eval.size(); ++i)
    u[i] = A * eval.scene().particles.referencePosition[i] + randomVector<D>(rng, 0.03 * dx);
  return u;
}

template <int D>
void expectForceIsMinusEnergyGradient(const std::string& material, std::uint32_t seed,
                                      GradientCorrection correction = GradientCorrection::Linear,
                                      double alpha = 0.0,
                                      HourglassGradient gradient = HourglassGradient::Corrected) {
  std::mt19937 rng(seed);
  const double dx = 0.01;
  std::array<int, D> counts;
  counts.fill(D == 2 ? 6 : 4);
  auto scene = sceneOf<D>(perturbedBlock<D>(counts, dx, 0.2, rng), dx, 2.5, testMaterial(material),
                          alpha, HourglassForm::Energy);
  scene.gradientCorrection = correction;
  scene.hourglassGradient = gradient;
  ForceEvaluator<D> eval(std::move(scene));
  auto u = randomDeformation(eval, dx, rng);
  const auto f = eval.force(u);
  double fmax = 0.0;
  for (const auto& fi : f)
    fmax = std::max(fmax, fi.cwiseAbs().maxCoeff());
  ASSERT_GT(fmax, 0.0);

  const double h = 1e-5 * dx;
  double worst = 0.0;
  for (Index i = 0; i < eval.size(); ++i)
    for (int a = 0; a < D; ++a) {
      const double saved = u[i][a];
      u[i][a] = saved + h;
      const double Eplus = eval.energy(u);
      u[i][a] = saved - h;
      const double Eminus = eval.energy(u);
      u[i][a] = saved;
      const double minusGradient = -(Eplus - Eminus) / (2 * h);
      worst = std::max(worst, std::abs(minusGradient - f[i][a]));
    }
  EXPECT_LT(worst, 1e-6 * fmax) << material << " in " << D << "D, alpha " << alpha;
}

template <int D>
void expectZeroTotalForce(const std::string& material, double alpha, std::uint32_t seed,
                          GradientCorrection correction = GradientCorrection::Linear) {
  std::mt19937 rng(seed);
  const double dx = 0.01;
  std::array<int, D> counts;
  counts.fill(D == 2 ? 7 : 4);
  auto scene =
      sceneOf<D>(perturbedBlock<D>(counts, dx, 0.2, rng), dx, 2.5, testMaterial(material), alpha);
  scene.gradientCorrection = correction;
  ForceEvaluator<D> eval(std::move(scene));
  const auto f = eval.force(randomDeformation(eval, dx, rng));
  Vec<D> total = Vec<D>::Zero();
  double scale = 0.0;
  for (const auto& fi : f) {
    total += fi;
    scale += fi.norm();
  }
  EXPECT_LT(total.norm(), 1e-13 * scale) << material << " in " << D << "D";
}

}  // namespace

class InternalForce : public ::testing::TestWithParam<std::string> {};

TEST_P(InternalForce, IsMinusEnergyGradient2D) {
  expectForceIsMinusEnergyGradient<2>(GetParam(), 21);
}
TEST_P(InternalForce, IsMinusEnergyGradient3D) {
  expectForceIsMinusEnergyGradient<3>(GetParam(), 22);
}
TEST_P(InternalForce, ConservesLinearMomentum2D) {
  expectZeroTotalForce<2>(GetParam(), 0.0, 23);
}
TEST_P(InternalForce, ConservesLinearMomentum3D) {
  expectZeroTotalForce<3>(GetParam(), 0.0, 24);
}
TEST_P(InternalForce, ConservesLinearMomentumWithHourglass) {
  expectZeroTotalForce<2>(GetParam(), 5.0, 25);
  expectZeroTotalForce<3>(GetParam(), 5.0, 26);
}
// The quadratic gradient correction changes F, so the force must follow it: still -dE/du.
TEST_P(InternalForce, IsMinusEnergyGradientQuadraticCorrection2D) {
  expectForceIsMinusEnergyGradient<2>(GetParam(), 27, GradientCorrection::Quadratic);
}
TEST_P(InternalForce, IsMinusEnergyGradientQuadraticCorrection3D) {
  expectForceIsMinusEnergyGradient<3>(GetParam(), 28, GradientCorrection::Quadratic);
}
TEST_P(InternalForce, ConservesLinearMomentumQuadraticCorrection) {
  expectZeroTotalForce<2>(GetParam(), 5.0, 29, GradientCorrection::Quadratic);
  expectZeroTotalForce<3>(GetParam(), 5.0, 30, GradientCorrection::Quadratic);
}

// The energy-form penalty (the default): f = -d(E + E_hg)/du with either correction and either
// F in e_IJ; alpha = 10 makes the penalty a large part of the force on a noisy field.
TEST_P(InternalForce, WithEnergyHourglassIsMinusEnergyGradient) {
  const auto lin = GradientCorrection::Linear, quad = GradientCorrection::Quadratic;
  expectForceIsMinusEnergyGradient<2>(GetParam(), 31, lin, 10.0);
  expectForceIsMinusEnergyGradient<3>(GetParam(), 32, lin, 10.0);
  expectForceIsMinusEnergyGradient<2>(GetParam(), 33, quad, 10.0);
  expectForceIsMinusEnergyGradient<3>(GetParam(), 34, quad, 10.0);
  expectForceIsMinusEnergyGradient<2>(GetParam(), 35, quad, 10.0, HourglassGradient::Linear);
  expectForceIsMinusEnergyGradient<3>(GetParam(), 36, quad, 10.0, HourglassGradient::Linear);
}

INSTANTIATE_TEST_SUITE_P(Materials, InternalForce,
                         ::testing::Values("linear-elastic", "saint-venant-kirchhoff",
                                           "neo-hookean", "mooney-rivlin"),
                         [](const auto& info) {
                           std::string name = info.param;
                           std::erase(name, '-');
                           return name;
                         });
