// The internal force (6.70) on the plain loops (method/InternalForce.hpp): minus the gradient
// of the discrete strain energy E = sum V_I psi(F_I) (which pins the sign of (6.70) and the
// transpose of L), with either gradient correction; it conserves linear momentum, and angular
// momentum for every objective material (E is then invariant under rigid rotations).
#include <gtest/gtest.h>

#include <variant>

#include "PlainEvaluator.hpp"

using namespace tlsph;
using namespace tlsph::testing;

namespace {

// A random smooth-ish deformation: finite affine part plus particle-wise noise.
template <int D>
std::vector<Vec<D>> randomDeformation(const PlainEvaluator<D>& eval, double dx, std::mt19937& rng) {
  const Mat<D> A = randomMatrix<D>(rng, 0.08);
  std::vector<Vec<D>> u(eval.size());
  for (Index i = 0; i < eval.size(); ++i)
    u[i] = A * eval.X()[i] + randomVector<D>(rng, 0.03 * dx);
  return u;
}

template <int D>
Scene<D> blockScene(const std::string& material, double alpha, std::uint32_t size,
                    GradientCorrection correction, std::mt19937& rng) {
  const double dx = 0.01;
  std::array<int, D> counts;
  counts.fill(D == 2 ? size + 2 : size);
  auto scene = sceneOf<D>(perturbedBlock<D>(counts, dx, 0.2, rng), dx, 2.5, testMaterial(material),
                          alpha, HourglassForm::Energy);
  scene.gradientCorrection = correction;
  return scene;
}

template <int D>
void expectForceIsMinusEnergyGradient(const std::string& material, std::uint32_t seed,
                                      GradientCorrection correction = GradientCorrection::Linear) {
  std::mt19937 rng(seed);
  const double dx = 0.01;
  PlainEvaluator<D> eval(blockScene<D>(material, 0.0, 4, correction, rng));
  const auto u = randomDeformation(eval, dx, rng);
  double fmax = 0.0;
  const double worst = energyGradientError<D>(eval, u, 1e-5 * dx, fmax);
  ASSERT_GT(fmax, 0.0);
  EXPECT_LT(worst, 1e-6 * fmax) << material << " in " << D << "D";
}

template <int D>
void expectZeroTotalForce(const std::string& material, double alpha, std::uint32_t seed,
                          GradientCorrection correction = GradientCorrection::Linear) {
  std::mt19937 rng(seed);
  const double dx = 0.01;
  PlainEvaluator<D> eval(blockScene<D>(material, alpha, D == 2 ? 5 : 4, correction, rng));
  const auto u = randomDeformation(eval, dx, rng);
  const auto f = eval.force(u);
  Vec<D> total = Vec<D>::Zero();
  double scale = 0.0, armScale = 0.0;
  const auto x = eval.currentPositions(u);
  for (Index i = 0; i < eval.size(); ++i) {
    total += f[i];
    scale += f[i].norm();
    armScale += x[i].norm() * f[i].norm();
  }
  EXPECT_LT(total.norm(), 1e-13 * scale) << material << " in " << D << "D";
  const bool objective =
      std::visit([](const auto& m) { return m.objective; }, eval.scene().materials[0]);
  if (objective) {
    EXPECT_LT(torque<D>(x, f).norm(), 1e-12 * armScale) << material << " in " << D << "D";
  }
}

}  // namespace

class InternalForce : public ::testing::TestWithParam<std::string> {};

TEST_P(InternalForce, IsMinusEnergyGradient2D) {
  expectForceIsMinusEnergyGradient<2>(GetParam(), 21);
}
TEST_P(InternalForce, IsMinusEnergyGradient3D) {
  expectForceIsMinusEnergyGradient<3>(GetParam(), 22);
}
TEST_P(InternalForce, ConservesMomentum2D) {
  expectZeroTotalForce<2>(GetParam(), 0.0, 23);
}
TEST_P(InternalForce, ConservesMomentum3D) {
  expectZeroTotalForce<3>(GetParam(), 0.0, 24);
}
TEST_P(InternalForce, ConservesMomentumWithHourglass) {
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
TEST_P(InternalForce, ConservesMomentumQuadraticCorrection) {
  expectZeroTotalForce<2>(GetParam(), 5.0, 29, GradientCorrection::Quadratic);
  expectZeroTotalForce<3>(GetParam(), 5.0, 30, GradientCorrection::Quadratic);
}

// The chapter's gather form with the linear correction: f_I = V_I sum_J V_J (P_I L_I^{-T} +
// P_J L_J^{-T}) gradW_IJ is the pair sum written from I's side.
TEST(InternalForceForm, PairSumIsTheChaptersGatherForm) {
  std::mt19937 rng(41);
  PlainEvaluator<2> eval(blockScene<2>("neo-hookean", 0.0, 5, GradientCorrection::Linear, rng));
  const auto u = randomDeformation(eval, 0.01, rng);
  const auto f = eval.force(u);
  const auto& ref = eval.reference();
  const auto& F = eval.forces().deformationGradient();
  const auto& V = eval.scene().particles.volume;
  double worst = 0.0, scale = 0.0;
  for (Index i = 0; i < eval.size(); ++i) {
    const auto& m = eval.scene().materials[0];
    const Mat<2> Bi = firstPiolaKirchhoff<2>(m, F[i]) * ref.correctionInverse[i].transpose();
    Vec<2> gathered = Vec<2>::Zero();
    for (Index k = ref.neighbours.offset[i]; k < ref.neighbours.offset[i + 1]; ++k) {
      const Index j = ref.neighbours.neighbour[k];
      const Mat<2> Bj = firstPiolaKirchhoff<2>(m, F[j]) * ref.correctionInverse[j].transpose();
      gathered += V[i] * (Bi + Bj) * ref.weightedGradient[k];  // w_IJ = V_J gradW_IJ
    }
    worst = std::max(worst, (gathered - f[i]).norm());
    scale = std::max(scale, f[i].norm());
  }
  ASSERT_GT(scale, 0.0);
  EXPECT_LT(worst, 1e-12 * scale);
}

INSTANTIATE_TEST_SUITE_P(Materials, InternalForce,
                         ::testing::Values("linear-elastic", "saint-venant-kirchhoff",
                                           "neo-hookean", "mooney-rivlin"),
                         [](const auto& info) {
                           std::string name = info.param;
                           std::erase(name, '-');
                           return name;
                         });
