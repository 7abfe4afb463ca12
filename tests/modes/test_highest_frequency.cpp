// The highest frequency of the discrete operator (highestFrequency) and the explicit step's cap
// on it: Lanczos' omega_max^2 is the largest eigenvalue of the dense generalised problem
// K phi = lambda M phi on jittered 2D and 3D blocks (both corrections, both quadratures,
// penalty on and off, free and clamped); and it is the stability limit of the explicit step:
// an undamped run at 0.95 x 2 / omega_max keeps its energy, one at 1.05 x blows up.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <random>

#include "ModesTestScenes.hpp"
#include "TestSupport.hpp"
#include "app/SpectralLimit.hpp"
#include "modes/ExactStiffness.hpp"
#include "modes/HighestFrequency.hpp"

using namespace tlsph;
using namespace tlsph::testing;

namespace {

template <int D>
Scene<D> jitteredBlock(const Numerics& n, double jitter, unsigned seed) {
  std::mt19937 rng(seed);
  std::array<int, D> counts;
  counts.fill(4);
  counts[0] = D == 2 ? 10 : 6;
  if constexpr (D == 2) counts[1] = 6;
  Scene<D> scene = sceneOf<D>(perturbedBlock<D>(counts, 0.01, jitter, rng), 0.01, 2.1,
                              testMaterial("neo-hookean"), n.alpha);
  scene.gradientCorrection = parseGradientCorrection(n.correction);
  scene.quadrature = parseQuadrature(n.quadrature);
  return scene;
}

// lambda_max of K phi = lambda M phi from the exact K, densely.
template <int D>
double denseLargest(Scene<D>& scene) {
  TangentAt<D> t(scene);
  const ExactStiffness e =
      exactStiffness(t.K, t.solver.reference(), t.dofs, scene.hourglass().enabled(), 100'000'000);
  EXPECT_TRUE(e.made) << e.reason;
  const ExactStiffness::Matrix full = e.lower.template selfadjointView<Eigen::Lower>();
  const Eigen::MatrixXd K = Eigen::MatrixXd(full);
  const Eigen::VectorXd s = t.mass.cwiseInverse().cwiseSqrt();
  const Eigen::MatrixXd A = s.asDiagonal() * K * s.asDiagonal();
  return Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(A, Eigen::EigenvaluesOnly)
      .eigenvalues()
      .maxCoeff();
}

const Numerics kNumerics[] = {{"linear", "nodal", 0.0},
                              {"linear", "nodal", 10.0},
                              {"quadratic", "nodal", 10.0},
                              {"quadratic", "taylor", 0.0},
                              {"quadratic", "taylor", 10.0}};

template <int D>
void expectDenseLargest(double jitter) {
  for (const auto& n : kNumerics) {
    Scene<D> scene = jitteredBlock<D>(n, jitter, 7);
    Solver<D> solver(scene);
    const SpectralEstimate f = highestFrequency(scene, solver.reference(), 1e-8);
    ASSERT_TRUE(f.made) << f.why;
    const double dense = denseLargest<D>(scene);
    EXPECT_NEAR(f.lambda, dense, 1e-7 * dense) << D << "D " << n.correction << " " << n.quadrature
                                               << " alpha " << n.alpha << " jitter " << jitter;
    EXPECT_GE(f.particle, 0);
  }
}

TEST(HighestFrequency, IsTheLargestEigenvalueIn2D) {
  expectDenseLargest<2>(0.0);
  expectDenseLargest<2>(0.1);
}

TEST(HighestFrequency, IsTheLargestEigenvalueIn3D) {
  expectDenseLargest<3>(0.0);
  expectDenseLargest<3>(0.1);
}

TEST(HighestFrequency, SeesThroughClampsAndHeldParticles) {
  for (const char* hold : {"clamp", "prescribe"}) {
    SceneSetup<2> setup = setupOf<2>(bodyText<2>(Shape::Box, {"quadratic", "taylor", 10.0}, hold));
    Solver<2> solver(setup.scene);
    const SpectralEstimate f = highestFrequency(setup.scene, solver.reference(), 1e-8);
    ASSERT_TRUE(f.made) << f.why;
    EXPECT_NEAR(f.lambda, denseLargest<2>(setup.scene), 1e-7 * f.lambda) << hold;
  }
}

TEST(HighestFrequency, NotMadeForTheTextbookForce) {
  Scene<2> scene = jitteredBlock<2>({"quadratic", "taylor", 10.0}, 0.0, 7);
  scene.hourglassForm = HourglassForm::Ganzenmueller;
  Solver<2> solver(scene);
  const SpectralEstimate f = highestFrequency(scene, solver.reference());
  EXPECT_FALSE(f.made);
  EXPECT_NE(f.why.find("not the gradient of an energy"), std::string::npos) << f.why;
}

// The largest relative change of the energy books over an undamped run at dt = factor x
// 2 / omega_max, from small random velocities (the linear regime).
template <int D>
double energyErrorAt(double factor, const Numerics& n) {
  Scene<D> scene = jitteredBlock<D>(n, 0.15, 11);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (auto& v : scene.particles.velocity)
    for (int a = 0; a < D; ++a)
      v[a] = 1e-4 * unit(rng);
  const SpectralEstimate f = [&] {
    Solver<D> s(scene);
    return highestFrequency(scene, s.reference(), 1e-8);
  }();
  EXPECT_TRUE(f.made);
  Solver<D> solver(scene, {kDefaultCfl, factor * f.criticalStep()});
  const double initial = solver.energyBalance().kinetic;
  double worst = 0.0;
  for (int step = 0; step < 400; ++step) {
    solver.step();
    const EnergyBalance e = solver.energyBalance();
    if (!std::isfinite(e.total())) return std::numeric_limits<double>::infinity();
    worst = std::max(worst, std::abs(e.kinetic + e.strain + e.hourglass - initial) / initial);
  }
  return worst;
}

TEST(HighestFrequency, IsTheExplicitStepsStabilityLimit) {
  // Below the limit Verlet's full-step energy of a mode at omega dt = 2 f is off its conserved
  // value by up to a factor 1 / (1 - f^2) (10.3 at f = 0.95): bounded; above it, growth by
  // |mu| ~ 1.4 per step.
  const double bound = 1.0 / (1.0 - 0.95 * 0.95);
  for (const Numerics& n :
       {Numerics{"quadratic", "taylor", 10.0}, Numerics{"linear", "nodal", 0.0}}) {
    const double below2 = energyErrorAt<2>(0.95, n), above2 = energyErrorAt<2>(1.05, n);
    EXPECT_LT(below2, bound) << n.correction;
    EXPECT_GT(above2, 1e3) << n.correction;
    const double below3 = energyErrorAt<3>(0.95, n), above3 = energyErrorAt<3>(1.05, n);
    EXPECT_LT(below3, bound) << n.correction;
    EXPECT_GT(above3, 1e3) << n.correction;
  }
}

TEST(SpectralStep, CapsTheRuleOffTheLatticeOnly) {
  const Numerics defaults{"quadratic", "taylor", 10.0};
  for (double jitter : {0.0, 0.15}) {
    Scene<3> scene = jitteredBlock<3>(defaults, jitter, 7);
    Solver<3> solver(scene);
    const double rule = solver.timeStep();
    solver.limitTimeStep(estimateSpectralStep(scene, solver));
    const SpectralStep& cap = solver.spectralStep();
    ASSERT_TRUE(cap.made);
    EXPECT_DOUBLE_EQ(cap.limit, 0.8 * 2.0 / std::sqrt(cap.lambda));
    EXPECT_EQ(solver.timeStep(), std::min(rule, cap.limit));
    EXPECT_EQ(cap.binds, cap.limit < rule);
    if (jitter == 0.0) {
      EXPECT_FALSE(cap.binds) << "the lattice keeps the rule's step";
    }
  }
  // [time] dt given: kept
  Scene<3> scene = jitteredBlock<3>(defaults, 0.15, 7);
  Solver<3> solver(scene, {kDefaultCfl, 1.0});
  solver.limitTimeStep(estimateSpectralStep(scene, solver));
  EXPECT_EQ(solver.timeStep(), 1.0);
}

}  // namespace
