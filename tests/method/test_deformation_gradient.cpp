// The corrected deformation gradient (6.69) is exact for affine displacement fields at every
// particle, boundary particles included; singular correction tensors are setup errors.
#include <gtest/gtest.h>

#include "TestSupport.hpp"
#include "model/Errors.hpp"

using namespace tlsph;
using namespace tlsph::testing;

namespace {

template <int D>
void expectAffineExactness(KernelType kernel, double supportRatio, std::uint32_t seed) {
  std::mt19937 rng(seed);
  const double dx = 0.01;
  std::array<int, D> counts;
  counts.fill(D == 2 ? 9 : 5);
  auto scene = sceneOf<D>(perturbedBlock<D>(counts, dx, 0.25, rng), dx, supportRatio,
                          testMaterial("neo-hookean"));
  scene.kernel = kernel;
  ForceEvaluator<D> eval(std::move(scene));
  for (int trial = 0; trial < 5; ++trial) {
    const Mat<D> A = Mat<D>::Identity() + randomMatrix<D>(rng, 0.4);
    const Vec<D> b = randomVector<D>(rng, 0.05);
    std::vector<Vec<D>> u(eval.size());
    for (Index i = 0; i < eval.size(); ++i) {
      const Vec<D>& X = eval.scene().particles.referencePosition[i];
      u[i] = (A - Mat<D>::Identity()) * X + b;
    }
    eval.force(u);
    const auto& F = eval.forces().deformationGradient();
    for (Index i = 0; i < eval.size(); ++i)
      ASSERT_LT((F[i] - A).norm(), 1e-12 * A.norm())
          << "particle " << i << " with " << eval.reference().neighbours.count(i) << " neighbours";
  }
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

TEST(DeformationGradient, CorrectionTensorIsSymmetricPositiveDefinite) {
  // With a radial kernel, gradW_IJ is parallel to X_IJ, so every term of (6.44) is a
  // positive multiple of X_IJ (x) X_IJ: L_I is symmetric positive definite on any cloud.
  // (So the transpose of L in B = P L^{-T} cannot be told apart by a force test; the
  // -dE/du test pins the sign and the rest of (6.70).)
  std::mt19937 rng(15);
  const double dx = 0.01;
  ForceEvaluator<2> eval(
      sceneOf<2>(perturbedBlock<2>({6, 6}, dx, 0.3, rng), dx, 2.5, testMaterial("linear-elastic")));
  for (const auto& Linv : eval.reference().correctionInverse) {
    EXPECT_LT((Linv - Linv.transpose()).norm(), 1e-12 * Linv.norm());
    EXPECT_GT(Linv.trace(), 0.0);        // a symmetric 2x2 matrix is positive definite iff
    EXPECT_GT(Linv.determinant(), 0.0);  // its trace and determinant are positive
  }
}

TEST(DeformationGradient, IsolatedParticleIsASetupError) {
  const double dx = 0.01;
  auto X = cellCentredLattice<3>(Vec3::Zero(), {4, 4, 4}, dx);
  X.push_back(Vec3(1.0, 1.0, 1.0));  // far from the block
  try {
    ForceEvaluator<3> eval(sceneOf<3>(X, dx, 2.2, testMaterial("linear-elastic")));
    FAIL() << "expected a SetupError";
  } catch (const SetupError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("particle 64"), std::string::npos) << what;
    EXPECT_NE(what.find("0 neighbours"), std::string::npos) << what;
    EXPECT_NE(what.find("singular"), std::string::npos) << what;
  }
}

TEST(DeformationGradient, SingleLayerIn3DIsASetupError) {
  // One layer of particles spans only a plane: L is rank 2.
  const double dx = 0.01;
  const auto X = cellCentredLattice<3>(Vec3::Zero(), {5, 5, 1}, dx);
  EXPECT_THROW(ForceEvaluator<3>(sceneOf<3>(X, dx, 2.5, testMaterial("linear-elastic"))),
               SetupError);
}
