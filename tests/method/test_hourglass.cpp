// The hourglass penalty, both forms: the energy form (the default; docs/method.md section 2) and the
// textbook (6.80, 6.81). Each conserves linear and angular momentum, is zero for every affine
// deformation and finite rigid rotation, and opposes a zig-zag mode. The energy form on the
// quadratic-corrected F is zero for quadratic fields (pure bending), on the linear F it is not.
#include <gtest/gtest.h>

#include "TestSupport.hpp"

using namespace tlsph;
using namespace tlsph::testing;

namespace {

template <int D>
Vec3 torque(const std::vector<Vec<D>>& x, const std::vector<Vec<D>>& f) {
  Vec3 sum = Vec3::Zero();
  for (std::size_t i = 0; i < x.size(); ++i) {
    Vec3 xi = Vec3::Zero(), fi = Vec3::Zero();
    xi.template head<D>() = x[i];
    fi.template head<D>() = f[i];
    sum += xi.cross(fi);
  }
  return sum;
}

// The hourglass part of the force: the force with the penalty minus the force without it, on
// the same cloud (the energy form adds a stress to P, so it has no separate pair force).
template <int D>
struct HourglassCase {
  std::mt19937 rng;
  double dx = 0.01;
  ForceEvaluator<D> with, without;
  HourglassCase(std::uint32_t seed, HourglassForm form,
                GradientCorrection correction = GradientCorrection::Linear,
                HourglassGradient gradient = HourglassGradient::Corrected)
      : rng(seed),
        with(scene(cloud(rng), 10.0, form, correction, gradient)),
        without(scene(with.scene().particles.referencePosition, 0.0, form, correction, gradient)) {}
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
  const std::vector<Vec<D>>& X() const { return with.scene().particles.referencePosition; }

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

template <int D>
void expectQuadraticFieldsAreFreeOnTheCorrectedGradient(std::uint32_t seed) {
  const auto quad = GradientCorrection::Quadratic;
  HourglassCase<D> corrected(seed, HourglassForm::Energy, quad, HourglassGradient::Corrected);
  HourglassCase<D> linear(seed, HourglassForm::Energy, quad, HourglassGradient::Linear);
  const double reference = corrected.largest(corrected.noisy(0.01));
  const auto u = quadraticField<D>(corrected.X(), corrected.rng);
  const double onCorrected = corrected.largest(u), onLinear = linear.largest(u);
  std::cout << D << "D quadratic field: largest hourglass force / that of noise "
            << onCorrected / reference << " on the quadratic F, " << onLinear / reference
            << " on the linear F\n";
  EXPECT_LT(onCorrected, 1e-8 * reference);
  EXPECT_GT(onLinear, 1e-3 * reference);
}

template <int D>
void expectOpposesZigZag(HourglassForm form) {
  // A checkerboard displacement on a regular lattice is invisible to F in the interior
  // (a zero-energy mode); the penalty force points against it: f . u < 0.
  const double dx = 0.01;
  std::array<int, D> counts;
  counts.fill(D == 2 ? 10 : 5);
  const auto X = cellCentredLattice<D>(Vec<D>::Zero(), counts, dx);
  ForceEvaluator<D> with(sceneOf<D>(X, dx, 2.0, testMaterial("linear-elastic"), 10.0, form));
  ForceEvaluator<D> without(sceneOf<D>(X, dx, 2.0, testMaterial("linear-elastic"), 0.0, form));
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

const auto kEnergy = HourglassForm::Energy;
const auto kTextbook = HourglassForm::Ganzenmueller;

}  // namespace

TEST(Hourglass, ConservesLinearAndAngularMomentum) {
  expectMomentumConservation<2>(31, kEnergy);
  expectMomentumConservation<3>(32, kEnergy);
  expectMomentumConservation<2>(31, kTextbook);
  expectMomentumConservation<3>(32, kTextbook);
}
TEST(Hourglass, VanishesForAffineDeformationAndRotation) {
  expectVanishesForAffineAndRotation<2>(33, kEnergy);
  expectVanishesForAffineAndRotation<3>(34, kEnergy);
  expectVanishesForAffineAndRotation<2>(33, kTextbook);
  expectVanishesForAffineAndRotation<3>(34, kTextbook);
}
TEST(Hourglass, EnergyFormOnQuadraticGradientIsFreeInBending) {
  expectQuadraticFieldsAreFreeOnTheCorrectedGradient<2>(36);
  expectQuadraticFieldsAreFreeOnTheCorrectedGradient<3>(37);
}
TEST(Hourglass, OpposesAZigZagMode) {
  expectOpposesZigZag<2>(kEnergy);
  expectOpposesZigZag<3>(kEnergy);
  expectOpposesZigZag<2>(kTextbook);
  expectOpposesZigZag<3>(kTextbook);
}

TEST(Hourglass, OffMeansNotComputed) {
  std::mt19937 rng(35);
  for (auto form : {kEnergy, kTextbook}) {
    ForceEvaluator<2> eval(sceneOf<2>(perturbedBlock<2>({5, 5}, 0.01, 0.2, rng), 0.01, 2.5,
                                      testMaterial("linear-elastic"), 0.0, form));
    EXPECT_FALSE(eval.forces().hourglassEnabled());
    eval.force(std::vector<Vec<2>>(eval.size(), Vec<2>::Zero()));
    EXPECT_TRUE(eval.forces().hourglassForce().empty());
    EXPECT_EQ(eval.forces().hourglassEnergy(std::vector<Vec<2>>(eval.size(), Vec<2>::Zero())), 0.0);
  }
}

// The textbook force is the pair force (6.80) itself; the solver books its work.
TEST(Hourglass, TextbookFormExposesItsPairForce) {
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
}
