// The reference configuration (method/ReferenceConfiguration.hpp): L_I^{-1} inverts the
// correction tensor (6.44), which is symmetric positive definite for a radial kernel; the
// gradient vectors g_IJ reproduce the gradient of every linear field (and with the quadratic
// correction of every quadratic field) at every particle; G_I and t_IJ are their sums and
// reverse pairs; singular neighbourhoods are setup errors, and neighbourhoods too thin for the
// quadratic fit fall back to the linear correction.
#include <gtest/gtest.h>

#include "TestSupport.hpp"
#include "model/Errors.hpp"

using namespace tlsph;
using namespace tlsph::testing;

namespace {

constexpr double kDx = 0.01;

template <int D>
struct Cloud {
  std::vector<Vec<D>> X;
  std::vector<double> V;
  ReferenceConfiguration<D> ref;
  Cloud(std::uint32_t seed, GradientCorrection correction, double supportRatio = 2.5) {
    std::mt19937 rng(seed);
    std::array<int, D> counts;
    counts.fill(D == 2 ? 8 : 5);
    X = perturbedBlock<D>(counts, kDx, 0.25, rng);
    V.assign(X.size(), std::pow(kDx, D));
    ref = buildReferenceConfiguration<D>(
        X, V, Kernel<D>(KernelType::WendlandC2, supportRatio * kDx), {}, correction);
  }
  // sum_J (f_J - f_I) g_IJ for the field values f (one vector per particle): grad f^T rows.
  Mat<D> gradient(Index i, const std::vector<Vec<D>>& f, const PairArray<Vec<D>>& g) const {
    Mat<D> G = Mat<D>::Zero();
    for (Index k = ref.neighbours.offset[i]; k < ref.neighbours.offset[i + 1]; ++k)
      G += (f[ref.neighbours.neighbour[k]] - f[i]) * g[k].transpose();
    return G;
  }
};

template <int D>
void expectCorrectionInverse(std::uint32_t seed) {
  const Cloud<D> c(seed, GradientCorrection::Linear);
  const auto& nb = c.ref.neighbours;
  for (Index i = 0; i < c.ref.particleCount(); ++i) {
    Mat<D> L = Mat<D>::Zero();  // (6.44): L_I = sum_J V_J (X_J - X_I) (x) gradW_IJ
    for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k)
      L -= c.ref.separation[k] * c.ref.weightedGradient[k].transpose();
    EXPECT_LT((L * c.ref.correctionInverse[i] - Mat<D>::Identity()).norm(), 1e-12) << i;
  }
}

template <int D>
void expectLinearFieldsReproduced(GradientCorrection correction, std::uint32_t seed) {
  const Cloud<D> c(seed, correction);
  std::mt19937 rng(seed);
  const Mat<D> A = randomMatrix<D>(rng, 1.0);
  const Vec<D> b = randomVector<D>(rng, 1.0);
  std::vector<Vec<D>> f(c.X.size());
  for (std::size_t i = 0; i < f.size(); ++i)
    f[i] = A * c.X[i] + b;
  const auto& linear =
      c.ref.linearGradient.empty() ? c.ref.correctedGradient : c.ref.linearGradient;
  for (Index i = 0; i < c.ref.particleCount(); ++i) {
    EXPECT_LT((c.gradient(i, f, c.ref.correctedGradient) - A).norm(), 1e-12 * A.norm()) << i;
    EXPECT_LT((c.gradient(i, f, linear) - A).norm(), 1e-12 * A.norm()) << i;
  }
}

template <int D>
void expectQuadraticFieldsReproduced(std::uint32_t seed) {
  const Cloud<D> c(seed, GradientCorrection::Quadratic);
  ASSERT_TRUE(c.ref.linearFallback.empty());
  std::mt19937 rng(seed);
  const Mat<D> A = randomMatrix<D>(rng, 0.1);
  std::array<Mat<D>, D> C;  // f_a = A_a . X + 1/2 X^T C_a X
  for (auto& Ca : C) {
    const Mat<D> r = randomMatrix<D>(rng, 5.0);
    Ca = r + r.transpose();
  }
  std::vector<Vec<D>> f(c.X.size());
  for (std::size_t i = 0; i < f.size(); ++i) {
    f[i] = A * c.X[i];
    for (int a = 0; a < D; ++a)
      f[i][a] += 0.5 * c.X[i].dot(C[a] * c.X[i]);
  }
  double worstQuadratic = 0.0, worstLinear = 0.0;
  for (Index i = 0; i < c.ref.particleCount(); ++i) {
    Mat<D> exact = A;
    for (int a = 0; a < D; ++a)
      exact.row(a) += (C[a] * c.X[i]).transpose();
    worstQuadratic = std::max(
        worstQuadratic, (c.gradient(i, f, c.ref.correctedGradient) - exact).norm() / exact.norm());
    worstLinear = std::max(worstLinear,
                           (c.gradient(i, f, c.ref.linearGradient) - exact).norm() / exact.norm());
  }
  EXPECT_LT(worstQuadratic, 1e-9);
  EXPECT_GT(worstLinear, 1e-3);  // the linear vectors read the neighbourhood's centroid
}

template <int D>
void expectSumsAndReversePairs(GradientCorrection correction, std::uint32_t seed) {
  const Cloud<D> c(seed, correction);
  const auto& nb = c.ref.neighbours;
  for (Index i = 0; i < c.ref.particleCount(); ++i) {
    Vec<D> G = Vec<D>::Zero();
    for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k) {
      const Index j = nb.neighbour[k];
      G += c.ref.correctedGradient[k];
      // (J, I) in J's list: t_IJ = (V_J / V_I) g_JI
      for (Index m = nb.offset[j]; m < nb.offset[j + 1]; ++m)
        if (nb.neighbour[m] == i) {
          EXPECT_EQ(c.ref.reverseGradient[k], (c.V[j] / c.V[i]) * c.ref.correctedGradient[m]);
        }
    }
    EXPECT_LT((G - c.ref.correctedGradientSum[i]).norm(),
              1e-12 * c.ref.correctedGradientSum[i].norm() + 1e-9);
  }
}

}  // namespace

TEST(ReferenceConfiguration, CorrectionInverseInvertsL) {
  expectCorrectionInverse<2>(61);
  expectCorrectionInverse<3>(62);
}

TEST(ReferenceConfiguration, GradientVectorsReproduceLinearFields) {
  expectLinearFieldsReproduced<2>(GradientCorrection::Linear, 63);
  expectLinearFieldsReproduced<3>(GradientCorrection::Linear, 64);
  expectLinearFieldsReproduced<2>(GradientCorrection::Quadratic, 65);
  expectLinearFieldsReproduced<3>(GradientCorrection::Quadratic, 66);
}

TEST(ReferenceConfiguration, QuadraticGradientVectorsReproduceQuadraticFields) {
  expectQuadraticFieldsReproduced<2>(67);
  expectQuadraticFieldsReproduced<3>(68);
}

TEST(ReferenceConfiguration, SumsAndReversePairs) {
  expectSumsAndReversePairs<2>(GradientCorrection::Linear, 69);
  expectSumsAndReversePairs<3>(GradientCorrection::Quadratic, 70);
}

TEST(ReferenceConfiguration, CorrectionTensorIsSymmetricPositiveDefinite) {
  // With a radial kernel, gradW_IJ is parallel to X_IJ, so every term of (6.44) is a
  // positive multiple of X_IJ (x) X_IJ: L_I is symmetric positive definite on any cloud.
  // (So the transpose of L in B = P L^{-T} cannot be told apart by a force test; the
  // -dE/du test pins the sign and the rest of (6.70).)
  std::mt19937 rng(15);
  const auto X = perturbedBlock<2>({6, 6}, kDx, 0.3, rng);
  const std::vector<double> V(X.size(), kDx * kDx);
  const auto ref =
      buildReferenceConfiguration<2>(X, V, Kernel<2>(KernelType::WendlandC2, 2.5 * kDx));
  for (const auto& Linv : ref.correctionInverse) {
    EXPECT_LT((Linv - Linv.transpose()).norm(), 1e-12 * Linv.norm());
    EXPECT_GT(Linv.trace(), 0.0);        // a symmetric 2x2 matrix is positive definite iff
    EXPECT_GT(Linv.determinant(), 0.0);  // its trace and determinant are positive
  }
}

TEST(ReferenceConfiguration, IsolatedParticleIsASetupError) {
  auto X = cellCentredLattice<3>(Vec3::Zero(), {4, 4, 4}, kDx);
  X.push_back(Vec3(1.0, 1.0, 1.0));  // far from the block
  const std::vector<double> V(X.size(), kDx * kDx * kDx);
  try {
    buildReferenceConfiguration<3>(X, V, Kernel<3>(KernelType::WendlandC2, 2.2 * kDx));
    FAIL() << "expected a SetupError";
  } catch (const SetupError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("particle 64"), std::string::npos) << what;
    EXPECT_NE(what.find("0 neighbours"), std::string::npos) << what;
    EXPECT_NE(what.find("singular"), std::string::npos) << what;
  }
}

TEST(ReferenceConfiguration, SingleLayerIn3DIsASetupError) {
  // One layer of particles spans only a plane: L is rank 2.
  const auto X = cellCentredLattice<3>(Vec3::Zero(), {5, 5, 1}, kDx);
  const std::vector<double> V(X.size(), kDx * kDx * kDx);
  EXPECT_THROW(buildReferenceConfiguration<3>(X, V, Kernel<3>(KernelType::WendlandC2, 2.5 * kDx)),
               SetupError);
}

TEST(ReferenceConfiguration, TooFewNeighboursForTheFitFallsBackToTheLinearCorrection) {
  // A 2-particle-thick strip: the fit across its thickness has no second-order term to use,
  // so every particle keeps the linear correction, which is still exact for affine fields,
  // and says so (ReferenceConfiguration::linearFallback).
  const auto X = cellCentredLattice<2>(Vec<2>::Zero(), {8, 2}, kDx);
  const Kernel<2> kernel(KernelType::WendlandC2, 1.5 * kDx);
  const std::vector<double> V(X.size(), kDx * kDx);
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
  const auto block = cellCentredLattice<2>(Vec<2>::Zero(), {6, 6}, kDx);
  const std::vector<double> Vb(block.size(), kDx * kDx);
  EXPECT_TRUE(buildReferenceConfiguration<2>(block, Vb,
                                             Kernel<2>(KernelType::WendlandC2, 2.1 * kDx), {},
                                             GradientCorrection::Quadratic)
                  .linearFallback.empty());
}
