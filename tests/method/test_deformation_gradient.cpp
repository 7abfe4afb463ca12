// The deformation gradient (6.69) on the plain loops (method/DeformationGradient.hpp): exact
// for affine displacement fields at every particle, boundary particles included, with either
// correction (and the linear F kept beside the quadratic one too); with the quadratic
// correction exact for quadratic fields at every particle, surface particles included, where
// the linear correction is not. That is what lets a beam's outer fibres carry their full
// bending strain.
#include <gtest/gtest.h>

#include "PlainEvaluator.hpp"
#include "method/DeformationGradient.hpp"

using namespace tlsph;
using namespace tlsph::testing;

namespace {

template <int D>
void expectAffineExactness(KernelType kernel, double supportRatio, std::uint32_t seed,
                           GradientCorrection correction = GradientCorrection::Linear) {
  std::mt19937 rng(seed);
  const double dx = 0.01;
  std::array<int, D> counts;
  counts.fill(D == 2 ? 9 : 5);
  auto scene = sceneOf<D>(perturbedBlock<D>(counts, dx, 0.25, rng), dx, supportRatio,
                          testMaterial("neo-hookean"));
  scene.kernel = kernel;
  scene.gradientCorrection = correction;
  PlainEvaluator<D> eval(std::move(scene));
  for (int trial = 0; trial < 5; ++trial) {
    const Mat<D> A = Mat<D>::Identity() + randomMatrix<D>(rng, 0.4);
    const Vec<D> b = randomVector<D>(rng, 0.05);
    std::vector<Vec<D>> u(eval.size());
    for (Index i = 0; i < eval.size(); ++i)
      u[i] = (A - Mat<D>::Identity()) * eval.X()[i] + b;
    eval.force(u);
    const auto& F = eval.forces().deformationGradient();
    const auto Flinear =
        deformationGradients<D>(eval.reference(), linearGradientVectors(eval.reference()), u);
    for (Index i = 0; i < eval.size(); ++i) {
      ASSERT_LT((F[i] - A).norm(), 1e-12 * A.norm())
          << "particle " << i << " with " << eval.reference().neighbours.count(i) << " neighbours";
      ASSERT_LT((Flinear[i] - A).norm(), 1e-12 * A.norm()) << "linear F, particle " << i;
      // H = F - 1 summed without the 1: exact to the rounding of H itself
      const Mat<D> H = displacementGradientAt<D>(eval.reference().neighbours,
                                                 eval.reference().correctedGradient, u, i);
      const Mat<D> exactH = A - Mat<D>::Identity();
      ASSERT_LT((H - exactH).norm(), 1e-12 * exactH.norm()) << "H, particle " << i;
    }
  }
}

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
  PlainEvaluator<D> eval(std::move(scene));
  const auto field = randomQuadratic<D>(rng, 5.0);  // curvature 5/m over a 0.05-0.09 m block
  std::vector<Vec<D>> u(eval.size());
  const auto& X = eval.X();
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

TEST(DeformationGradient, AffineExact2D) {
  expectAffineExactness<2>(KernelType::WendlandC2, 2.5, 11);
  expectAffineExactness<2>(KernelType::CubicBSpline, 3.0, 12);
}

TEST(DeformationGradient, AffineExact3D) {
  expectAffineExactness<3>(KernelType::WendlandC2, 2.5, 13);
  expectAffineExactness<3>(KernelType::CubicBSpline, 2.2, 14);
}

TEST(DeformationGradient, AffineExactQuadraticCorrection) {
  expectAffineExactness<2>(KernelType::WendlandC2, 2.5, 15, GradientCorrection::Quadratic);
  expectAffineExactness<3>(KernelType::WendlandC2, 2.5, 16, GradientCorrection::Quadratic);
}

TEST(DeformationGradient, QuadraticCorrectionExactForQuadraticFields2D) {
  EXPECT_LT(worstGradientError<2>(GradientCorrection::Quadratic, 0.25, 2.5, 51), 1e-9);
  EXPECT_LT(worstGradientError<2>(GradientCorrection::Quadratic, 0.0, 2.1, 52), 1e-9);
}

TEST(DeformationGradient, QuadraticCorrectionExactForQuadraticFields3D) {
  EXPECT_LT(worstGradientError<3>(GradientCorrection::Quadratic, 0.25, 2.5, 53), 1e-9);
  EXPECT_LT(worstGradientError<3>(GradientCorrection::Quadratic, 0.0, 2.1, 54), 1e-9);
}

TEST(DeformationGradient, LinearCorrectionIsNotExactAtTheSurface) {
  // The contrast that motivates the quadratic correction: (6.69) errs by O(curvature dx) on
  // the surface.
  EXPECT_GT(worstGradientError<2>(GradientCorrection::Linear, 0.0, 2.1, 52), 1e-2);
  EXPECT_GT(worstGradientError<3>(GradientCorrection::Linear, 0.0, 2.1, 54), 1e-2);
}
