// Zero-energy modes (chapter section 6.13): the null space of the discrete stiffness
// K = -df/du at u = 0 of the plain evaluation (method/PairForces.hpp). On a periodic lattice
// the uncorrected scheme has spurious exact zero modes that the hourglass penalty removes; on a
// free block only rigid-body modes are exact zeros, and the spurious modes survive as
// low-energy modes.
#include <gtest/gtest.h>

#include <Eigen/SVD>

#include "PlainEvaluator.hpp"

using namespace tlsph;
using namespace tlsph::testing;

namespace {

constexpr double kDx = 0.01;

// -df/du by central differences, Richardson-extrapolated: exact for the linear internal force,
// O(s^4) for the hourglass term (nonlinear through x_IJ / |x_IJ|).
template <int D>
Eigen::MatrixXd stiffness(PlainEvaluator<D>& eval) {
  const Index n = eval.size() * D;
  auto centralDifference = [&](double s) {
    Eigen::MatrixXd K(n, n);
    std::vector<Vec<D>> u(eval.size(), Vec<D>::Zero());
    for (Index c = 0; c < n; ++c) {
      u[c / D][c % D] = s;
      const auto plus = eval.force(u);
      u[c / D][c % D] = -s;
      const auto minus = eval.force(u);
      u[c / D][c % D] = 0.0;
      for (Index r = 0; r < n; ++r)
        K(r, c) = -(plus[r / D][r % D] - minus[r / D][r % D]) / (2 * s);
    }
    return K;
  };
  const double s = 1e-3 * kDx;
  return (4.0 * centralDifference(0.5 * s) - centralDifference(s)) / 3.0;
}

struct Spectrum {
  int zeros = 0;               // singular values below 1e-10 of the largest
  double lowestNonZero = 0.0;  // relative to the largest
};

Spectrum spectrum(const Eigen::MatrixXd& K) {
  const Eigen::VectorXd sigma = Eigen::BDCSVD<Eigen::MatrixXd>(K).singularValues();
  Spectrum s;
  for (Eigen::Index k = 0; k < sigma.size(); ++k)
    if (sigma[k] < 1e-10 * sigma[0]) ++s.zeros;
  s.lowestNonZero = sigma[sigma.size() - 1 - s.zeros] / sigma[0];
  return s;
}

template <int D>
Spectrum latticeSpectrum(int cellsPerAxis, bool periodic, double supportRatio, double alpha,
                         GradientCorrection correction = GradientCorrection::Linear,
                         HourglassForm form = HourglassForm::Energy) {
  std::array<int, D> counts;
  counts.fill(cellsPerAxis);
  auto scene = sceneOf<D>(cellCentredLattice<D>(Vec<D>::Zero(), counts, kDx), kDx, supportRatio,
                          testMaterial("linear-elastic"), alpha, form);
  scene.gradientCorrection = correction;
  if (periodic) {
    scene.periodicBox.periodic.fill(true);
    scene.periodicBox.length = Vec<D>::Constant(cellsPerAxis * kDx);
  }
  PlainEvaluator<D> eval(std::move(scene));
  return spectrum(stiffness(eval));
}

}  // namespace

TEST(ZeroEnergyModes, PeriodicLatticeWithoutPenaltyHasSpuriousModes) {
  EXPECT_EQ(latticeSpectrum<2>(8, true, 2.0, 0.0).zeros, 8);
  EXPECT_EQ(latticeSpectrum<3>(4, true, 2.0, 0.0).zeros, 24);
}

// Both forms of the penalty: the energy form (the default) and the textbook (6.80).
TEST(ZeroEnergyModes, PenaltyLeavesOnlyTranslationsOnPeriodicLattice) {
  EXPECT_EQ(latticeSpectrum<2>(8, true, 2.0, 10.0).zeros, 2);
  EXPECT_EQ(latticeSpectrum<3>(4, true, 2.0, 10.0).zeros, 3);
  const auto lin = GradientCorrection::Linear;
  EXPECT_EQ(latticeSpectrum<2>(8, true, 2.0, 10.0, lin, HourglassForm::Ganzenmueller).zeros, 2);
  EXPECT_EQ(latticeSpectrum<3>(4, true, 2.0, 10.0, lin, HourglassForm::Ganzenmueller).zeros, 3);
}

TEST(ZeroEnergyModes, FreeBlockHasOnlyRigidBodyZeros) {
  for (double alpha : {0.0, 10.0}) {
    EXPECT_EQ(latticeSpectrum<2>(8, false, 2.0, alpha).zeros, 3) << "alpha " << alpha;
    EXPECT_EQ(latticeSpectrum<3>(4, false, 2.0, alpha).zeros, 6) << "alpha " << alpha;
  }
}

TEST(ZeroEnergyModes, PenaltyStiffensTheLowEnergyModesOfAFreeBlock) {
  const Spectrum without = latticeSpectrum<2>(8, false, 3.0, 0.0);
  const Spectrum with = latticeSpectrum<2>(8, false, 3.0, 10.0);
  ASSERT_EQ(without.zeros, 3);
  ASSERT_EQ(with.zeros, 3);
  std::cout << "8x8 free block, support 3 dx: lowest non-zero singular value / largest = "
            << without.lowestNonZero << " without penalty, " << with.lowestNonZero
            << " with alpha = 10\n";
  EXPECT_GT(with.lowestNonZero / without.lowestNonZero, 10.0);
}

// The default: quadratic correction with the energy penalty on the same (quadratic) F. The
// penalty vanishes for quadratic fields but not for the spurious modes: the periodic lattice
// keeps only the translations and a free block only its rigid-body modes.
TEST(ZeroEnergyModes, QuadraticCorrectionWithPenaltyHasOnlyPhysicalZeros) {
  const auto q = GradientCorrection::Quadratic;
  EXPECT_EQ(latticeSpectrum<2>(8, true, 2.1, 10.0, q).zeros, 2);
  EXPECT_EQ(latticeSpectrum<3>(5, true, 2.1, 10.0, q).zeros, 3);
  EXPECT_EQ(latticeSpectrum<2>(8, false, 2.5, 10.0, q).zeros, 3);
  EXPECT_EQ(latticeSpectrum<3>(4, false, 2.5, 10.0, q).zeros, 6);
  std::cout << "quadratic, periodic 8x8, support 2.1 dx, no penalty: "
            << latticeSpectrum<2>(8, true, 2.1, 0.0, q).zeros << " zero modes\n";
}
