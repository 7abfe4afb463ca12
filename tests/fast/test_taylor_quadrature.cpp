// The second-order quadrature correction of the strain energy (TaylorQuadrature):
// the force is -dE/du of E = sum_I V_I psi(F_I) + E_q (+ E_hg) by central differences, the
// tangent's product is the central difference of the force, and on a cell-centred lattice the
// corrected energy of a quadratic displacement field is the exact integral of the linear-elastic
// energy density over the body (the nodal sum alone misses 1/n^2 of the bending energy).
#include <gtest/gtest.h>

#include <bit>
#include <cstdint>

#include "DifferencedStiffness.hpp"
#include "TestSupport.hpp"
#include "explicit/Solver.hpp"
#include "implicit/DofMap.hpp"
#include "implicit/TangentStiffness.hpp"

using namespace tlsph;
using namespace tlsph::testing;

namespace {

constexpr double kDx = 0.01;

template <int D>
Scene<D> blockScene(const std::string& material, double alpha, double jitter, std::mt19937& rng,
                    bool taylor = true) {
  std::array<int, D> counts;
  counts.fill(D == 2 ? 6 : 4);
  counts[0] = D == 2 ? 8 : 5;
  auto X = perturbedBlock<D>(counts, kDx, jitter, rng);
  Scene<D> scene = sceneOf<D>(X, kDx, 2.4, testMaterial(material), alpha);
  scene.gradientCorrection = GradientCorrection::Quadratic;
  scene.quadrature = taylor ? Quadrature::Taylor : Quadrature::Nodal;
  return scene;
}

template <int D>
void expectForceIsMinusEnergyGradient(const std::string& material, double alpha,
                                      std::uint32_t seed) {
  std::mt19937 rng(seed);
  ForceEvaluator<D> eval(blockScene<D>(material, alpha, 0.15, rng));
  ASSERT_NE(eval.forces().quadrature(), nullptr);
  const Index n = eval.size();
  const Mat<D> A = randomMatrix<D>(rng, 0.1);
  std::vector<Vec<D>> u(n);
  for (Index i = 0; i < n; ++i) {
    const Vec<D>& X = eval.scene().particles.referencePosition[i];
    u[i] = A * X + X.squaredNorm() / kDx * randomVector<D>(rng, 0.01) +
           randomVector<D>(rng, 0.03 * kDx);
  }
  const auto f = eval.force(u);
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
      error = std::max(error, std::abs(fd - f[i][a]));
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
void expectTangentIsForceDifference(double alpha, std::uint32_t seed) {
  std::mt19937 rng(seed);
  Scene<D> scene = blockScene<D>("neo-hookean", alpha, 0.15, rng);
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
                        scene.hourglass(), dofs, scene.quadrature);
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

// u_i = A_ij X_j + 1/2 B_ijk X_j X_k (B symmetric in j, k); the exact integral of the linear
// elastic energy density over the block by 3-point Gauss rules per axis (exact: the density is
// quadratic in X).
template <int D>
void expectExactForQuadraticFields(std::uint32_t seed) {
  std::mt19937 rng(seed);
  Scene<D> scene = blockScene<D>("linear-elastic", 0.0, 0.0, rng);
  Vec<D> upper = Vec<D>::Zero();
  for (const auto& X : scene.particles.referencePosition)
    upper = upper.cwiseMax(X);
  upper.array() += 0.5 * kDx;
  const double amplitude = 1e-7;
  const Mat<D> A = randomMatrix<D>(rng, amplitude);
  std::array<Mat<D>, D> B;  // B[i](j, k)
  for (auto& b : B) {
    b = randomMatrix<D>(rng, amplitude / kDx);
    b = Mat<D>(0.5 * (b + b.transpose()).eval());
  }
  auto gradient = [&](const Vec<D>& X) {
    Mat<D> H = A;
    for (int i = 0; i < D; ++i)
      H.row(i) += (B[i] * X).transpose();
    return H;
  };
  const auto& c = elasticConstants(scene.materials[0]);
  auto density = [&](const Vec<D>& X) {
    const Mat<D> H = gradient(X);
    const Mat<D> eps = 0.5 * (H + H.transpose());
    return 0.5 * c.lambda * eps.trace() * eps.trace() + c.mu * (eps.array() * eps.array()).sum();
  };
  const double g = std::sqrt(0.6);
  const std::array<double, 3> node = {-g, 0.0, g}, weight = {5.0 / 9, 8.0 / 9, 5.0 / 9};
  double exact = 0.0;
  std::array<int, D> idx{};
  const int total = D == 2 ? 9 : 27;
  for (int m = 0; m < total; ++m) {
    int r = m;
    Vec<D> X;
    double w = 1.0;
    for (int a = 0; a < D; ++a) {
      idx[a] = r % 3;
      r /= 3;
      X[a] = 0.5 * upper[a] * (1.0 + node[idx[a]]);
      w *= 0.5 * upper[a] * weight[idx[a]];
    }
    exact += w * density(X);
  }
  ForceEvaluator<D> corrected(scene);
  scene.quadrature = Quadrature::Nodal;
  ForceEvaluator<D> nodal(scene);
  EXPECT_TRUE(corrected.reference().linearFallback.empty());
  std::vector<Vec<D>> u(corrected.size());
  for (Index i = 0; i < corrected.size(); ++i) {
    const Vec<D>& X = scene.particles.referencePosition[i];
    u[i] = A * X;
    for (int k = 0; k < D; ++k)
      u[i][k] += 0.5 * X.dot(B[k] * X);
  }
  const double Ec = corrected.energy(u), En = nodal.energy(u);
  SCOPED_TRACE("D=" + std::to_string(D) + " nodal " + std::to_string(En / exact));
  // F and its gradient are exact at every particle (the quadratic fit)
  for (Index i = 0; i < corrected.size(); ++i) {
    const Vec<D>& X = scene.particles.referencePosition[i];
    const Mat<D> H = gradient(X);
    EXPECT_LT((corrected.forces().deformationGradient()[i] - Mat<D>::Identity() - H).norm(),
              1e-8 * A.norm());
    const auto G =
        TaylorQuadrature<D>::unpack(corrected.forces().quadrature()->secondGradients()[i]);
    for (int a = 0; a < D; ++a)
      for (int k = 0; k < D; ++k)
        EXPECT_LT((G[a].row(k) - B[k].row(a)).norm(), 1e-8 * B[k].norm()) << i << " " << a;
  }
  EXPECT_NEAR(Ec, exact, 1e-6 * exact);
  EXPECT_GT(std::abs(En - exact), 1e-3 * exact);  // the nodal sum alone is not exact
}

TEST(TaylorQuadrature, ExactForQuadraticFieldsOnALattice) {
  expectExactForQuadraticFields<2>(31);
  expectExactForQuadraticFields<3>(32);
}

}  // namespace
