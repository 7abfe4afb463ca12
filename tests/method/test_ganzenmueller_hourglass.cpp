// The textbook hourglass force (6.80)-(6.81) (method/GanzenmuellerHourglass.hpp) on the plain
// loops: it conserves linear and angular momentum (a central, antisymmetric pair force), is
// zero for every affine deformation and finite rigid rotation, opposes a zig-zag mode, is the
// pair force (6.80) itself as exposed for the solver's work books, and is not the gradient of
// an energy.
#include <gtest/gtest.h>

#include <cmath>

#include "HourglassCase.hpp"

using namespace tlsph;
using namespace tlsph::testing;

namespace {
const auto kTextbook = HourglassForm::Ganzenmueller;
}  // namespace

TEST(GanzenmuellerHourglass, ConservesLinearAndAngularMomentum) {
  expectMomentumConservation<2>(31, kTextbook);
  expectMomentumConservation<3>(32, kTextbook);
}
TEST(GanzenmuellerHourglass, VanishesForAffineDeformationAndRotation) {
  expectVanishesForAffineAndRotation<2>(33, kTextbook);
  expectVanishesForAffineAndRotation<3>(34, kTextbook);
}
TEST(GanzenmuellerHourglass, OpposesAZigZagMode) {
  expectOpposesZigZag<2>(kTextbook);
  expectOpposesZigZag<3>(kTextbook);
}
TEST(GanzenmuellerHourglass, OffMeansNotComputed) {
  expectOffMeansNotComputed<2>(kTextbook, 35);
  expectOffMeansNotComputed<3>(kTextbook, 39);
}

// The textbook force is the pair force (6.80) itself; the solver books its work.
TEST(GanzenmuellerHourglass, ExposesItsPairForce) {
  HourglassCase<2> c(38, kTextbook);
  const auto u = c.noisy(0.02);
  const auto f = c.hourglassForce(u);
  const auto& fhg = c.with.forces().hourglassForce();
  ASSERT_EQ(fhg.size(), f.size());
  double worst = 0.0, scale = 0.0;
  for (std::size_t i = 0; i < f.size(); ++i) {
    worst = std::max(worst, (f[i] - fhg[i]).norm());
    scale = std::max(scale, fhg[i].norm());
  }
  EXPECT_LT(worst, 1e-9 * scale);
  // it books no energy of its own
  EXPECT_EQ(c.with.forces().hourglassEnergy(u), 0.0);
}

// Not conservative: its work around a closed loop in displacement space is not zero, which is
// why the energy form exists. The loop u(t) = a cos t + b sin t in 400 midpoint steps: for a
// linear force K u the sum is N sin(h/2) (a.Kb - b.Ka), zero exactly when K is symmetric, as
// for the energy form (E_hg is quadratic in u); the textbook force's K is not.
namespace {
double loopWork(HourglassForm form, double& scale) {
  HourglassCase<2> c(40, form);
  const auto a = c.noisy(0.05), b = c.noisy(0.05);
  const int steps = 400;
  auto at = [&](double t) {
    std::vector<Vec<2>> u(a.size());
    for (std::size_t i = 0; i < a.size(); ++i)
      u[i] = std::cos(t) * a[i] + std::sin(t) * b[i];
    return u;
  };
  double work = 0.0;
  scale = 0.0;
  for (int s = 0; s < steps; ++s) {
    const double t0 = 2 * M_PI * s / steps, t1 = 2 * M_PI * (s + 1) / steps;
    const auto u0 = at(t0), u1 = at(t1), um = at(0.5 * (t0 + t1));
    const auto f = c.hourglassForce(um);
    for (std::size_t i = 0; i < f.size(); ++i) {
      work += f[i].dot(u1[i] - u0[i]);
      scale += std::abs(f[i].dot(u1[i] - u0[i]));
    }
  }
  return work;
}
}  // namespace

TEST(GanzenmuellerHourglass, IsNotTheGradientOfAnEnergy) {
  double scale = 0.0;
  const double textbook = loopWork(kTextbook, scale);
  EXPECT_GT(std::abs(textbook), 1e-3 * scale);
  const double energy = loopWork(HourglassForm::Energy, scale);
  EXPECT_LT(std::abs(energy), 1e-11 * scale);
}
