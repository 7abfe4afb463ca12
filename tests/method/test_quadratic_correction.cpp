// The quadratic gradient correction: F is exact for quadratic displacement fields at every
// particle, surface particles included, where the linear correction (6.69) is not. This is what
// lets a beam's outer fibres carry their full bending strain (README, "Gradient correction").
#include <gtest/gtest.h>

#include "TestSupport.hpp"
#include "model/Errors.hpp"

using namespace tlsph;
using namespace tlsph::testing;

namespace {

// u = b + A X + 1/2 X^T C_a X per component a (C_a symmetric); grad u = A + [X^T C_a]_a.
template <int D>
struct QuadraticField {
  Vec<D> b;
  Mat<D> A;
  std::array<Mat<D>, D> C;

  Vec<D> operator()(const Vec<D>& X) const {
    Vec<D> u = b + A * X;
    for (int a = 0; a < D; ++a)
      u[a] += 0.5 * X.dot(C[a] * X);
    return u;
  }
  Mat<D> gradient(const Vec<D>& X) const {
    Mat<D> G = A;
    for (int a = 0; a < D; ++a)
      G.row(a) += (C[a] * X).transpose();
    return G;
  }
};

template <int D>
QuadraticField<D> randomQuadratic(std::mt19937& rng, double curvature) {
  QuadraticField<D> q{randomVector<D>(rng, 0.01), randomMatrix<D>(rng, 0.1), {}};
  for (auto& c : q.C) {
    const Mat<D> r = randomMatrix<D>(rng, curvature);
    c = r + r.transpose();
  }
  return q;
}

// Largest |F_I - (1 + grad u(X_I))| over the particles, relative to |grad u|.
template <int D>
double worstGradientError(GradientCorrection correction, double jitter, double supportRatio,
                          std::uint32_t seed) {
  std::mt19937 rng(seed);
  const double dx = 0.01;
  std::array<int, D> counts;
  counts.fill(D == 2 ? 9 : 5);
  auto scene = sceneOf<D>(perturbedBlock<D>(counts, dx, jitter, rng), dx, supportRatio,
                          testMaterial("neo-hookean"));
  scene.gradientCorrection = correction;
  ForceEvaluator<D> eval(std::move(scene));
  const auto field = randomQuadratic<D>(rng, 5.0);  // curvature 5/m over a 0.05-0.09 m block
  std::vector<Vec<D>> u(eval.size());
  const auto& X = eval.scene().particles.referencePosition;
  for (Index i = 0; i < eval.size(); ++i)
    u[i] = field(X[i]);
  eval.force(u);
  const auto& F = eval.forces().deformationGradient();
  double worst = 0.0;
  for (Index i = 0; i < eval.size(); ++i) {
    const Mat<D> exact = Mat<D>::Identity() + field.gradient(X[i]);
    worst = std::max(worst, (F[i] - exact).norm() / field.gradient(X[i]).norm());
  }
  return worst;
}

}  // namespace

TEST(QuadraticCorrection, ExactForQuadraticFields2D) {
  EXPECT_LT(worstGradientError<2>(GradientCorrection::Quadratic, 0.25, 2.5, 51), 1e-9);
  EXPECT_LT(worstGradientError<2>(GradientCorrection::Quadratic, 0.0, 2.1, 52), 1e-9);
}

TEST(QuadraticCorrection, ExactForQuadraticFields3D) {
  EXPECT_LT(worstGradientError<3>(GradientCorrection::Quadratic, 0.25, 2.5, 53), 1e-9);
  EXPECT_LT(worstGradientError<3>(GradientCorrection::Quadratic, 0.0, 2.1, 54), 1e-9);
}

TEST(QuadraticCorrection, LinearCorrectionIsNotExactAtTheSurface) {
  // The contrast that motivates the option: (6.69) errs by O(curvature dx) on the surface.
  EXPECT_GT(worstGradientError<2>(GradientCorrection::Linear, 0.0, 2.1, 52), 1e-2);
  EXPECT_GT(worstGradientError<3>(GradientCorrection::Linear, 0.0, 2.1, 54), 1e-2);
}

TEST(QuadraticCorrection, TooFewNeighboursForTheFitFallsBackToTheLinearCorrection) {
  // A 2-particle-thick strip: the fit across its thickness has no second-order term to use,
  // so every particle keeps the linear correction, which is still exact for affine fields,
  // and says so (ReferenceConfiguration::linearFallback).
  const double dx = 0.01;
  const auto X = cellCentredLattice<2>(Vec<2>::Zero(), {8, 2}, dx);
  const Kernel<2> kernel(KernelType::WendlandC2, 1.5 * dx);
  const std::vector<double> V(X.size(), dx * dx);
  const auto ref = buildReferenceConfiguration<2>(X, V, kernel, {}, GradientCorrection::Quadratic);
  EXPECT_EQ(ref.linearFallback.size(), X.size());
  Mat<2> A;
  A << 0.03, -0.2, 0.11, 0.05;
  double worst = 0.0;
  for (Index i = 0; i < ref.particleCount(); ++i) {
    Mat<2> G = Mat<2>::Zero();
    for (Index k = ref.neighbours.offset[i]; k < ref.neighbours.offset[i + 1]; ++k) {
      const Index j = ref.neighbours.neighbour[k];
      G += (A * (X[j] - X[i])) * ref.correctedGradient[k].transpose();
    }
    worst = std::max(worst, (G - A).norm());
  }
  EXPECT_LT(worst, 1e-12);
  // A full lattice block needs no fallback.
  const auto block = cellCentredLattice<2>(Vec<2>::Zero(), {6, 6}, dx);
  const std::vector<double> Vb(block.size(), dx * dx);
  EXPECT_TRUE(buildReferenceConfiguration<2>(block, Vb, Kernel<2>(KernelType::WendlandC2, 2.1 * dx),
                                             {}, GradientCorrection::Quadratic)
                  .linearFallback.empty());
}
