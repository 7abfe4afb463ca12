// The energy-form hourglass penalty (method/HourglassEnergy.hpp) on the plain loops: its force
// (spring plus hourglass stress through F's gradient vectors) is exactly -dE_hg/du, alone and
// with the strain energy, on the corrected and on the linear F; it conserves linear and angular
// momentum, vanishes for every affine deformation and rigid rotation, opposes a zig-zag mode,
// and on the quadratic-corrected F it vanishes for quadratic fields (pure bending), on the
// linear F it does not.
#include <gtest/gtest.h>

#include "HourglassCase.hpp"
#include "method/DeformationGradient.hpp"
#include "method/HourglassEnergy.hpp"
#include "method/HourglassStiffness.hpp"

using namespace tlsph;
using namespace tlsph::testing;

namespace {

const auto kEnergy = HourglassForm::Energy;

// u = random quadratic polynomial of X (every component), of the size of a bending field.
template <int D>
std::vector<Vec<D>> quadraticField(const std::vector<Vec<D>>& X, std::mt19937& rng) {
  const Mat<D> A = randomMatrix<D>(rng, 0.05);
  std::array<Mat<D>, D> B;
  for (auto& b : B)
    b = randomMatrix<D>(rng, 2.0);
  std::vector<Vec<D>> u(X.size());
  for (std::size_t i = 0; i < X.size(); ++i) {
    u[i] = A * X[i];
    for (int a = 0; a < D; ++a)
      u[i][a] += X[i].dot(B[a] * X[i]);
  }
  return u;
}

// E_hg(u) and -dE_hg/du of the penalty alone, F = F(u) through the gradient vectors g.
template <int D>
struct PenaltyAlone {
  const ReferenceConfiguration<D>& ref;
  const PairArray<double>& c;
  const std::vector<double>& V;
  const PairArray<Vec<D>>& g;
  Index size() const { return ref.particleCount(); }
  std::vector<Vec<D>> force(const std::vector<Vec<D>>& u) const {
    std::vector<Vec<D>> f(size(), Vec<D>::Zero());
    addHourglassForce<D>(ref, c, V, g, u, deformationGradients<D>(ref, g, u), f);
    return f;
  }
  double energy(const std::vector<Vec<D>>& u) const {
    return hourglassEnergy<D>(ref, c, V, u, deformationGradients<D>(ref, g, u));
  }
};

template <int D>
void expectPenaltyForceIsMinusItsEnergyGradient(GradientCorrection correction, bool linearF,
                                                std::uint32_t seed) {
  HourglassCase<D> hc(seed, kEnergy, correction);
  const auto& ref = hc.with.reference();
  const auto& V = hc.with.scene().particles.volume;
  const auto c = hourglassPairCoefficients<D>(ref, hc.with.scene().materials,
                                              hc.with.scene().particles.material, V, 10.0);
  const PenaltyAlone<D> penalty{ref, c, V,
                                linearF ? linearGradientVectors(ref) : ref.correctedGradient};
  auto u = quadraticField<D>(hc.X(), hc.rng);
  const auto noise = hc.noisy(0.02);
  for (Index i = 0; i < hc.with.size(); ++i)
    u[i] += noise[i];
  double fmax = 0.0;
  const double worst = energyGradientError<D>(penalty, u, 1e-5 * hc.dx, fmax);
  ASSERT_GT(fmax, 0.0);
  EXPECT_LT(worst, 1e-7 * fmax) << D << "D, " << (linearF ? "linear F" : "corrected F");
  EXPECT_GT(penalty.energy(u), 0.0);
}

template <int D>
void expectQuadraticFieldsAreFreeOnTheCorrectedGradient(std::uint32_t seed) {
  const auto quad = GradientCorrection::Quadratic;
  HourglassCase<D> corrected(seed, kEnergy, quad, HourglassGradient::Corrected);
  HourglassCase<D> linear(seed, kEnergy, quad, HourglassGradient::Linear);
  const double reference = corrected.largest(corrected.noisy(0.01));
  const auto u = quadraticField<D>(corrected.X(), corrected.rng);
  const double onCorrected = corrected.largest(u), onLinear = linear.largest(u);
  std::cout << D << "D quadratic field: largest hourglass force / that of noise "
            << onCorrected / reference << " on the quadratic F, " << onLinear / reference
            << " on the linear F\n";
  EXPECT_LT(onCorrected, 1e-8 * reference);
  EXPECT_GT(onLinear, 1e-3 * reference);
  // and the energy itself: zero on the quadratic F, not on the linear one
  corrected.with.force(u);
  linear.with.force(u);
  const double onCorrectedEnergy = corrected.with.forces().hourglassEnergy(u);
  const double onLinearEnergy = linear.with.forces().hourglassEnergy(u);
  EXPECT_GT(onLinearEnergy, 0.0);
  EXPECT_LT(onCorrectedEnergy, 1e-12 * onLinearEnergy);
}

template <int D>
void expectForceIsMinusEnergyGradient(const std::string& material, std::uint32_t seed,
                                      GradientCorrection correction, HourglassGradient gradient) {
  std::mt19937 rng(seed);
  const double dx = 0.01;
  std::array<int, D> counts;
  counts.fill(D == 2 ? 6 : 4);
  auto scene = sceneOf<D>(perturbedBlock<D>(counts, dx, 0.2, rng), dx, 2.5, testMaterial(material),
                          10.0, kEnergy);
  scene.gradientCorrection = correction;
  scene.hourglassGradient = gradient;
  PlainEvaluator<D> eval(std::move(scene));
  const Mat<D> A = randomMatrix<D>(rng, 0.08);
  std::vector<Vec<D>> u(eval.size());
  for (Index i = 0; i < eval.size(); ++i)
    u[i] = A * eval.X()[i] + randomVector<D>(rng, 0.03 * dx);
  double fmax = 0.0;
  const double worst = energyGradientError<D>(eval, u, 1e-5 * dx, fmax);
  ASSERT_GT(fmax, 0.0);
  EXPECT_LT(worst, 1e-6 * fmax) << material << " in " << D << "D";
}

}  // namespace

TEST(HourglassEnergy, ConservesLinearAndAngularMomentum) {
  expectMomentumConservation<2>(31, kEnergy);
  expectMomentumConservation<3>(32, kEnergy);
}
TEST(HourglassEnergy, VanishesForAffineDeformationAndRotation) {
  expectVanishesForAffineAndRotation<2>(33, kEnergy);
  expectVanishesForAffineAndRotation<3>(34, kEnergy);
}
TEST(HourglassEnergy, OnQuadraticGradientIsFreeInBending) {
  expectQuadraticFieldsAreFreeOnTheCorrectedGradient<2>(36);
  expectQuadraticFieldsAreFreeOnTheCorrectedGradient<3>(37);
}
TEST(HourglassEnergy, OpposesAZigZagMode) {
  expectOpposesZigZag<2>(kEnergy);
  expectOpposesZigZag<3>(kEnergy);
}
TEST(HourglassEnergy, OffMeansNotComputed) {
  expectOffMeansNotComputed<2>(kEnergy, 35);
  expectOffMeansNotComputed<3>(kEnergy, 38);
}
TEST(HourglassEnergy, PenaltyForceIsMinusItsEnergyGradient) {
  const auto lin = GradientCorrection::Linear, quad = GradientCorrection::Quadratic;
  expectPenaltyForceIsMinusItsEnergyGradient<2>(lin, false, 41);
  expectPenaltyForceIsMinusItsEnergyGradient<3>(lin, false, 42);
  expectPenaltyForceIsMinusItsEnergyGradient<2>(quad, false, 43);
  expectPenaltyForceIsMinusItsEnergyGradient<3>(quad, false, 44);
  expectPenaltyForceIsMinusItsEnergyGradient<2>(quad, true, 45);
  expectPenaltyForceIsMinusItsEnergyGradient<3>(quad, true, 46);
}

// With the strain energy: f = -d(E + E_hg)/du with either correction and either F in e_IJ;
// alpha = 10 makes the penalty a large part of the force on a noisy field.
class HourglassEnergyWithMaterial : public ::testing::TestWithParam<std::string> {};

TEST_P(HourglassEnergyWithMaterial, TotalForceIsMinusEnergyGradient) {
  const auto lin = GradientCorrection::Linear, quad = GradientCorrection::Quadratic;
  const auto corrected = HourglassGradient::Corrected, linear = HourglassGradient::Linear;
  expectForceIsMinusEnergyGradient<2>(GetParam(), 31, lin, corrected);
  expectForceIsMinusEnergyGradient<3>(GetParam(), 32, lin, corrected);
  expectForceIsMinusEnergyGradient<2>(GetParam(), 33, quad, corrected);
  expectForceIsMinusEnergyGradient<3>(GetParam(), 34, quad, corrected);
  expectForceIsMinusEnergyGradient<2>(GetParam(), 35, quad, linear);
  expectForceIsMinusEnergyGradient<3>(GetParam(), 36, quad, linear);
}

INSTANTIATE_TEST_SUITE_P(Materials, HourglassEnergyWithMaterial,
                         ::testing::Values("linear-elastic", "saint-venant-kirchhoff",
                                           "neo-hookean", "mooney-rivlin"),
                         [](const auto& info) {
                           std::string name = info.param;
                           std::erase(name, '-');
                           return name;
                         });
