// A jittered block with and without the hourglass penalty, on the plain loops: the penalty's
// part of the force is the difference of the two (the energy form adds a stress to P, so it
// has no separate pair force). Shared by the tests of both forms of the penalty.
#pragma once

#include <random>
#include <vector>

#include "PlainEvaluator.hpp"

namespace tlsph::testing {

template <int D>
struct HourglassCase {
  std::mt19937 rng;
  double dx = 0.01;
  PlainEvaluator<D> with, without;
  HourglassCase(std::uint32_t seed, HourglassForm form,
                GradientCorrection correction = GradientCorrection::Linear,
                HourglassGradient gradient = HourglassGradient::Corrected)
      : rng(seed),
        with(scene(cloud(rng), 10.0, form, correction, gradient)),
        without(scene(with.X(), 0.0, form, correction, gradient)) {}
  static std::vector<Vec<D>> cloud(std::mt19937& rng) {
    std::array<int, D> c;
    c.fill(D == 2 ? 7 : 4);
    return perturbedBlock<D>(c, 0.01, 0.2, rng);
  }
  static Scene<D> scene(const std::vector<Vec<D>>& X, double alpha, HourglassForm form,
                        GradientCorrection correction, HourglassGradient gradient) {
    auto s = sceneOf<D>(X, 0.01, 2.5, testMaterial("neo-hookean"), alpha, form);
    s.gradientCorrection = correction;
    s.hourglassGradient = gradient;
    return s;
  }
  const std::vector<Vec<D>>& X() const { return with.X(); }

  std::vector<Vec<D>> hourglassForce(const std::vector<Vec<D>>& u) {
    auto f = with.force(u);
    const auto f0 = without.force(u);
    for (std::size_t i = 0; i < f.size(); ++i)
      f[i] -= f0[i];
    return f;
  }
  double largest(const std::vector<Vec<D>>& u) {
    double m = 0.0;
    for (const auto& f : hourglassForce(u))
      m = std::max(m, f.norm());
    return m;
  }
  std::vector<Vec<D>> noisy(double amplitude) {
    std::vector<Vec<D>> u(with.size());
    for (auto& ui : u)
      ui = randomVector<D>(rng, amplitude * dx);
    return u;
  }
};

template <int D>
void expectMomentumConservation(std::uint32_t seed, HourglassForm form) {
  HourglassCase<D> c(seed, form);
  const Mat<D> A = randomMatrix<D>(c.rng, 0.2);
  auto u = c.noisy(0.05);
  for (Index i = 0; i < c.with.size(); ++i)
    u[i] += A * c.X()[i];
  const auto fhg = c.hourglassForce(u);
  const auto x = c.with.currentPositions(u);
  Vec<D> total = Vec<D>::Zero();
  double scale = 0.0, armScale = 0.0;
  for (Index i = 0; i < c.with.size(); ++i) {
    total += fhg[i];
    scale += fhg[i].norm();
    armScale += x[i].norm() * fhg[i].norm();
  }
  ASSERT_GT(scale, 0.0);
  EXPECT_LT(total.norm(), 1e-12 * scale);
  EXPECT_LT(torque<D>(x, fhg).norm(), 1e-12 * armScale);
}

template <int D>
void expectVanishesForAffineAndRotation(std::uint32_t seed, HourglassForm form) {
  HourglassCase<D> c(seed, form);
  const double reference = c.largest(c.noisy(0.01));  // a non-affine field of similar size
  ASSERT_GT(reference, 0.0);
  for (int trial = 0; trial < 4; ++trial) {
    const Mat<D> A = Mat<D>::Identity() + randomMatrix<D>(c.rng, 0.3);
    const Mat<D> R = randomRotation<D>(c.rng);
    const Vec<D> b = randomVector<D>(c.rng, 0.1);
    std::vector<Vec<D>> affine(c.with.size()), rotated(c.with.size());
    for (Index i = 0; i < c.with.size(); ++i) {
      affine[i] = (A - Mat<D>::Identity()) * c.X()[i] + b;
      rotated[i] = (R - Mat<D>::Identity()) * c.X()[i] + b;
    }
    EXPECT_LT(c.largest(affine), 1e-9 * reference) << "affine trial " << trial;
    EXPECT_LT(c.largest(rotated), 1e-9 * reference) << "rotation trial " << trial;
  }
}

template <int D>
void expectOpposesZigZag(HourglassForm form) {
  // A checkerboard displacement on a regular lattice is invisible to F in the interior
  // (a zero-energy mode); the penalty force points against it: f . u < 0.
  const double dx = 0.01;
  std::array<int, D> counts;
  counts.fill(D == 2 ? 10 : 5);
  const auto X = cellCentredLattice<D>(Vec<D>::Zero(), counts, dx);
  PlainEvaluator<D> with(sceneOf<D>(X, dx, 2.0, testMaterial("linear-elastic"), 10.0, form));
  PlainEvaluator<D> without(sceneOf<D>(X, dx, 2.0, testMaterial("linear-elastic"), 0.0, form));
  std::vector<Vec<D>> u(with.size(), Vec<D>::Zero());
  for (Index i = 0; i < with.size(); ++i) {
    int parity = 0;
    for (int a = 0; a < D; ++a)
      parity += static_cast<int>(X[i][a] / dx);
    u[i][0] = (parity % 2 ? 1e-4 : -1e-4) * dx;
  }
  const auto f = with.force(u), f0 = without.force(u);
  double power = 0.0;
  for (Index i = 0; i < with.size(); ++i)
    power += (f[i] - f0[i]).dot(u[i]);
  EXPECT_LT(power, 0.0);
}

// The penalty off: no force part, no energy.
template <int D>
void expectOffMeansNotComputed(HourglassForm form, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::array<int, D> counts;
  counts.fill(5);
  PlainEvaluator<D> eval(sceneOf<D>(perturbedBlock<D>(counts, 0.01, 0.2, rng), 0.01, 2.5,
                                    testMaterial("linear-elastic"), 0.0, form));
  const std::vector<Vec<D>> u(eval.size(), Vec<D>::Zero());
  eval.force(u);
  EXPECT_TRUE(eval.forces().hourglassForce().empty());
  EXPECT_TRUE(eval.forces().hourglassPairCoefficient().empty());
  EXPECT_EQ(eval.forces().hourglassEnergy(u), 0.0);
}

}  // namespace tlsph::testing
