// The second-order quadrature correction of the strain energy (TaylorQuadrature):
// the force is -dE/du of E = sum_I V_I psi(F_I) + E_q (+ E_hg) by central differences, the
// tangent's product is the central difference of the force, and two particles' padded sums are
// each particle's own. (The exactness for quadratic fields is pinned on the plain loops,
// tests/method/test_taylor_correction.cpp; tests/fast/test_equivalence.cpp holds this pass to
// them.) With general quadrature moments: the force and energy are the plain loops' and the
// tangent is the difference of the force.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>

#include "DifferencedStiffness.hpp"
#include "TestSupport.hpp"
#include "explicit/Solver.hpp"
#include "implicit/DofMap.hpp"
#include "implicit/TangentStiffness.hpp"
#include "method/PairForces.hpp"

using namespace tlsph;
using namespace tlsph::testing;

namespace {

constexpr double kDx = 0.01;

template <int D>
Scene<D> blockScene(const std::string& material, double alpha, double jitter, std::mt19937& rng,
                    bool taylor = true) {
  return taylorBlockScene<D>(material, alpha, jitter, rng, kDx, taylor);
}

template <int D>
void expectForceIsMinusEnergyGradient(const std::string& material, double alpha, std::uint32_t seed,
                                      bool moments = false) {
  std::mt19937 rng(seed);
  Scene<D> scene = blockScene<D>(material, alpha, 0.15, rng);
  if (moments) addRandomMoments<D>(scene, rng, kDx);
  ForceEvaluator<D> eval(scene);
  ASSERT_NE(eval.forces().quadrature(), nullptr);
  const Index n = eval.size();
  // with moments a milder field, whose J > 0 at every particle (random moments make the Taylor
  // term's stress large); a NaN energy fails the check below
  const double k = moments ? 0.25 : 0.5;
  const Mat<D> A = randomMatrix<D>(rng, 0.1 * k);
  std::vector<Vec<D>> u(n);
  for (Index i = 0; i < n; ++i) {
    const Vec<D>& X = eval.scene().particles.referencePosition[i];
    u[i] = A * X + X.squaredNorm() / kDx * randomVector<D>(rng, 0.01 * k) +
           randomVector<D>(rng, (moments ? 0.005 : 0.03) * kDx);
  }
  const auto f = eval.force(u);
  ASSERT_TRUE(std::isfinite(eval.energy(u))) << material << " D=" << D;
  const double h = 1e-6 * kDx;
  double scale = 0.0, error = 0.0;
  for (Index i = 0; i < n; ++i)
    for (int a = 0; a < D; ++a) {
      auto v = u;
      v[i][a] += h;
      const double plus = eval.energy(v);
      v[i][a] -= 2.0 * h;
      const double minus = eval.energy(v);
      const double fd = -(plus - minus) / (2.0 * h);
      scale = std::max(scale, std::abs(f[i][a]));
      error = worseOf(error, std::abs(fd - f[i][a]));
    }
  SCOPED_TRACE(material + " alpha " + std::to_string(alpha) + " D=" + std::to_string(D));
  EXPECT_GT(scale, 0.0);
  EXPECT_LT(error, 1e-6 * scale);
}

TEST(TaylorQuadrature, ForceIsMinusEnergyGradient2D) {
  for (const char* m : {"linear-elastic", "saint-venant-kirchhoff", "neo-hookean"})
    for (double alpha : {0.0, 10.0})
      expectForceIsMinusEnergyGradient<2>(m, alpha, 11);
}

TEST(TaylorQuadrature, ForceIsMinusEnergyGradientWithMoments) {
  for (const char* m : {"linear-elastic", "neo-hookean"}) {
    expectForceIsMinusEnergyGradient<2>(m, 10.0, 13, true);
    expectForceIsMinusEnergyGradient<3>(m, 10.0, 14, true);
  }
}

// With general moments the fused pass's force and energy are the plain loops'.
template <int D>
void expectPlainWithMoments(const std::string& material, std::uint32_t seed) {
  std::mt19937 rng(seed);
  Scene<D> scene = blockScene<D>(material, 10.0, 0.15, rng);
  addRandomMoments<D>(scene, rng, kDx);
  ForceEvaluator<D> fast(scene);
  ForceEvaluator<D, PairForces<D>> plain(scene);
  const Index n = fast.size();
  const Mat<D> A = randomMatrix<D>(rng, 0.05);
  std::vector<Vec<D>> u(n);
  for (Index i = 0; i < n; ++i) {
    const Vec<D>& X = scene.particles.referencePosition[i];
    u[i] = A * X + X.squaredNorm() / kDx * randomVector<D>(rng, 0.005) +
           randomVector<D>(rng, 0.01 * kDx);
  }
  const auto ff = fast.force(u), fp = plain.force(u);
  double scale = 0.0, error = 0.0;
  for (Index i = 0; i < n; ++i) {
    scale = std::max(scale, fp[i].cwiseAbs().maxCoeff());
    error = std::max(error, (ff[i] - fp[i]).cwiseAbs().maxCoeff());
  }
  SCOPED_TRACE(material + " D=" + std::to_string(D));
  EXPECT_GT(scale, 0.0);
  EXPECT_LT(error, 1e-11 * scale);
  for (const auto& F : plain.forces().deformationGradient())
    ASSERT_GT(F.determinant(), 0.0);  // a field every material takes
  const double Ef = fast.energy(u), Ep = plain.energy(u);
  ASSERT_TRUE(std::isfinite(Ep));
  EXPECT_NEAR(Ef, Ep, 1e-12 * std::abs(Ep));
}

TEST(TaylorQuadrature, PlainForceWithMoments) {
  for (const char* m : {"linear-elastic", "saint-venant-kirchhoff", "neo-hookean"}) {
    expectPlainWithMoments<2>(m, 15);
    expectPlainWithMoments<3>(m, 16);
  }
}

TEST(TaylorQuadrature, ForceIsMinusEnergyGradient3D) {
  for (const char* m : {"saint-venant-kirchhoff", "neo-hookean"})
    for (double alpha : {0.0, 10.0})
      expectForceIsMinusEnergyGradient<3>(m, alpha, 12);
}

// The F pass sums two particles at once: each particle's [grad u | Gs] must be the
// bits of its own sum, whatever its partner and whichever row is longer (a jittered block:
// rows of different lengths), with the padding row zero.
TEST(TaylorQuadrature, TwoParticleSumsAreEachParticlesOwn) {
  std::mt19937 rng(31);
  ForceEvaluator<3> eval(blockScene<3>("neo-hookean", 10.0, 0.15, rng));
  const TaylorQuadrature<3>& q = *eval.forces().quadrature();
  const Index n = eval.size();
  std::vector<PaddedVec<3>> u(n, PaddedVec<3>::Zero());
  for (Index i = 0; i < n; ++i)
    u[i].head<3>() = randomVector<3>(rng, 0.1 * kDx);
  const auto& nb = eval.reference().neighbours;
  int unequalRows = 0;
  for (Index i0 = 0; i0 < n; ++i0)
    for (Index i1 : {(i0 + 1) % n, (i0 + 7) % n, i0}) {
      TaylorQuadrature<3>::FitSum one0, one1, two0, two1;
      q.paddedGradients(i0, u, one0);
      q.paddedGradients(i1, u, one1);
      q.paddedGradients(i0, i1, u, two0, two1);
      unequalRows += nb.offset[i0 + 1] - nb.offset[i0] != nb.offset[i1 + 1] - nb.offset[i1];
      for (int m = 0; m < one0.cols(); ++m)
        for (int a = 0; a < 4; ++a) {
          ASSERT_EQ(std::bit_cast<std::uint64_t>(two0(a, m)),
                    std::bit_cast<std::uint64_t>(one0(a, m)))
              << "particle " << i0 << " with " << i1 << ", entry (" << a << ", " << m << ")";
          ASSERT_EQ(std::bit_cast<std::uint64_t>(two1(a, m)),
                    std::bit_cast<std::uint64_t>(one1(a, m)))
              << "particle " << i1 << " with " << i0 << ", entry (" << a << ", " << m << ")";
        }
      EXPECT_EQ(one0.row(3).squaredNorm(), 0.0);
      EXPECT_GT(one0.topRows<3>().squaredNorm(), 0.0);
    }
  EXPECT_GT(unequalRows, n);  // the tails of the longer row are exercised
}

template <int D>
void expectTangentIsForceDifference(double alpha, std::uint32_t seed, bool moments = false,
                                    const std::string& material = "neo-hookean") {
  std::mt19937 rng(seed);
  Scene<D> scene = blockScene<D>(material, alpha, 0.15, rng);
  if (moments) addRandomMoments<D>(scene, rng, kDx);
  auto& p = scene.particles;
  // hold the first layer
  Prescription<D> clamp;
  clamp.name = "held";
  for (Index i = 0; i < p.size(); ++i)
    if (p.referencePosition[i].x() < kDx) {
      p.motion[i] = Motion::Prescribed;
      clamp.particles.push_back(i);
    }
  scene.prescriptions.push_back(clamp);
  Solver<D> solver(scene);
  const Mat<D> A = randomMatrix<D>(rng, 0.08);
  for (Index i = 0; i < p.size(); ++i)
    if (p.motion[i] == Motion::Free)
      p.displacement[i] = A * p.referencePosition[i] +
                          p.referencePosition[i].squaredNorm() / kDx * randomVector<D>(rng, 0.01);
  solver.reevaluate();
  DofMap<D> dofs(p, scene.mirrorGhosts);
  TangentStiffness<D> K(solver.reference(), scene.materials, p.material, p.volume,
                        scene.hourglass(), dofs, scene.quadrature, p.quadratureMoments());
  K.update(solver.forces().deformationGradient());
  K.updateQuadrature(solver.forces().quadrature(), solver.forces().deformationGradient());
  EXPECT_FALSE(K.assemblyExact());
  const Index n = K.size();
  Eigen::MatrixXd applied(n, n);
  Eigen::VectorXd e = Eigen::VectorXd::Zero(n), column;
  for (Index k = 0; k < n; ++k) {
    e.setZero();
    e[k] = 1.0;
    K.apply(e, column);
    applied.col(k) = column;
  }
  const Eigen::MatrixXd differenced =
      differencedStiffness(solver, p.displacement, dofs.freeParticles(), 1e-6 * kDx);
  const double scale = differenced.cwiseAbs().maxCoeff();
  EXPECT_LT((applied - differenced).cwiseAbs().maxCoeff(), 1e-5 * scale);
  EXPECT_LT((applied - applied.transpose()).cwiseAbs().maxCoeff(), 1e-10 * scale);
}

TEST(TaylorQuadrature, TangentIsForceDifference) {
  expectTangentIsForceDifference<2>(0.0, 21);
  expectTangentIsForceDifference<2>(10.0, 22);
  expectTangentIsForceDifference<3>(10.0, 23);
}

TEST(TaylorQuadrature, TangentIsForceDifferenceWithMoments) {
  expectTangentIsForceDifference<2>(10.0, 24, true);
  expectTangentIsForceDifference<2>(0.0, 25, true, "linear-elastic");
  expectTangentIsForceDifference<3>(10.0, 26, true);
  expectTangentIsForceDifference<3>(10.0, 27, true, "saint-venant-kirchhoff");
}

}  // namespace
