// The hourglass penalty's pair coefficients (method/HourglassStiffness.hpp): c_IJ = alpha E_IJ
// V_J W(X_IJ) / |X_IJ|^2, so that k_IJ = V_I c_IJ is symmetric (balanced pair forces) across
// materials and volumes; passive particles count half with a body particle and not at all with
// each other; K_I = sum_J k_IJ.
#include <gtest/gtest.h>

#include "TestSupport.hpp"
#include "method/HourglassStiffness.hpp"

using namespace tlsph;
using namespace tlsph::testing;

namespace {

constexpr double kDx = 0.01;

struct TwoMaterialBlock {
  std::vector<Vec<2>> X;
  std::vector<double> V;
  std::vector<std::uint16_t> material;
  std::vector<Material> materials{
      makeMaterial("neo-hookean", ElasticConstants::fromYoungPoisson(2.0e6, 0.3), 1000.0),
      makeMaterial("linear-elastic", ElasticConstants::fromYoungPoisson(7.0e6, 0.25), 2000.0)};
  ReferenceConfiguration<2> ref;
  explicit TwoMaterialBlock(std::uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> scale(0.8, 1.2);
    X = perturbedBlock<2>({7, 6}, kDx, 0.2, rng);
    for (const auto& x : X) {
      V.push_back(kDx * kDx * scale(rng));  // unequal volumes
      material.push_back(x[0] < 0.035 ? 0 : 1);
    }
    ref = buildReferenceConfiguration<2>(X, V, Kernel<2>(KernelType::WendlandC2, 2.5 * kDx));
  }
  // the position of (j, i) in j's list
  Index reverse(Index i, Index j) const {
    const auto& nb = ref.neighbours;
    for (Index m = nb.offset[j]; m < nb.offset[j + 1]; ++m)
      if (nb.neighbour[m] == i) return m;
    return -1;
  }
};

}  // namespace

TEST(HourglassStiffness, PairCoefficientFormulaAndSymmetricStiffness) {
  const TwoMaterialBlock b(81);
  const double alpha = 7.5;
  const auto c = hourglassPairCoefficients<2>(b.ref, b.materials, b.material, b.V, alpha);
  const auto& nb = b.ref.neighbours;
  const double E[] = {2.0e6, 7.0e6};
  int interfaces = 0;
  for (Index i = 0; i < b.ref.particleCount(); ++i)
    for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k) {
      const Index j = nb.neighbour[k];
      const Vec<2> Xij = b.X[i] - b.X[j];
      const double W = Kernel<2>(KernelType::WendlandC2, 2.5 * kDx).value(Xij.norm());
      const double expected =
          alpha * 0.5 * (E[b.material[i]] + E[b.material[j]]) * b.V[j] * W / Xij.squaredNorm();
      EXPECT_NEAR(c[k], expected, 1e-12 * expected);
      const Index m = b.reverse(i, j);
      ASSERT_GE(m, 0);
      EXPECT_NEAR(b.V[i] * c[k], b.V[j] * c[m], 1e-12 * b.V[i] * c[k]);  // k_IJ = k_JI
      interfaces += b.material[i] != b.material[j];
    }
  EXPECT_GT(interfaces, 0);
}

TEST(HourglassStiffness, PassiveParticlesCountHalfWithTheBodyAndNotAtAllAmongThemselves) {
  const TwoMaterialBlock b(82);
  const auto full = hourglassPairCoefficients<2>(b.ref, b.materials, b.material, b.V, 10.0);
  std::vector<std::uint8_t> passive(b.X.size(), 0);
  for (std::size_t i = 0; i < b.X.size(); ++i)
    passive[i] = b.X[i][1] < 0.02;
  const auto c = hourglassPairCoefficients<2>(b.ref, b.materials, b.material, b.V, 10.0, passive);
  const auto& nb = b.ref.neighbours;
  int mixed = 0, ghostPairs = 0;
  for (Index i = 0; i < b.ref.particleCount(); ++i)
    for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k) {
      const Index j = nb.neighbour[k];
      const double weight = 1.0 - 0.5 * (passive[i] + passive[j]);
      EXPECT_EQ(c[k], full[k] * weight);
      mixed += passive[i] != passive[j];
      ghostPairs += passive[i] && passive[j];
      const Index m = b.reverse(i, j);
      EXPECT_NEAR(b.V[i] * c[k], b.V[j] * c[m], 1e-12 * b.V[i] * full[k]);
    }
  EXPECT_GT(mixed, 0);
  EXPECT_GT(ghostPairs, 0);
}

TEST(HourglassStiffness, ParticleStiffnessIsTheSumOfItsSprings) {
  const TwoMaterialBlock b(83);
  const auto c = hourglassPairCoefficients<2>(b.ref, b.materials, b.material, b.V, 10.0);
  const auto K = hourglassParticleStiffness<2>(b.ref, c, b.V);
  const auto& nb = b.ref.neighbours;
  ASSERT_EQ(K.size(), b.X.size());
  for (Index i = 0; i < b.ref.particleCount(); ++i) {
    double sum = 0.0;
    for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k)
      sum += b.V[i] * c[k];
    EXPECT_NEAR(K[i], sum, 1e-12 * sum);
    EXPECT_GT(K[i], 0.0);
  }
}
