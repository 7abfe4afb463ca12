// The pair loops' padded values (Padded.hpp): padding adds a zero fourth row and is
// nothing in 2D, transposing keeps the fourth row zero; and the force pass and the energy penalty,
// which gather padded S_J, R_J, F_J, u_J and X_IJ, give the force of the tangent's own loops, which
// use the plain D x D values: for the linear-elastic material the force (internal, energy penalty
// on either F, quadrature correction) is linear in u, so f(u) = -K u up to rounding.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <type_traits>

#include "TestSupport.hpp"
#include "fast/Padded.hpp"
#include "implicit/DofMap.hpp"
#include "implicit/TangentStiffness.hpp"

using namespace tlsph;
using namespace tlsph::testing;

namespace {

constexpr double kDx = 0.01;

static_assert(std::is_same_v<PaddedMat<2>, Mat<2>> && std::is_same_v<PaddedVec<2>, Vec<2>>);
static_assert(PaddedMat<3>::RowsAtCompileTime == 4 && PaddedMat<3, 6>::ColsAtCompileTime == 6);

TEST(Padded, AddsAZeroFourthRow) {
  Mat<3> m;
  m << 1, 2, 3, 4, 5, 6, 7, 8, 9;
  const PaddedMat<3> p = padded<3, 3>(m);
  EXPECT_EQ(p.topRows<3>(), m);
  EXPECT_EQ(p.row(3).squaredNorm(), 0.0);
  const PaddedVec<3> v = padded<3, 1>(Vec<3>(1, 2, 3));
  EXPECT_EQ(v, Eigen::Vector4d(1, 2, 3, 0));
}

// transposed() shuffles registers in 3D (AVX): every entry must land where Eigen's transpose
// puts it, and the fourth row stay zero.
TEST(Padded, TransposedIsTheTransposeWithAZeroFourthRow) {
  Mat<3> m;
  m << 1, 2, 3, 4, 5, 6, 7, 8, 9;
  const PaddedMat<3> t = transposed<3>(padded<3, 3>(m));
  EXPECT_EQ(Mat<3>(t.topRows<3>()), Mat<3>(m.transpose()));
  EXPECT_EQ(t.row(3).squaredNorm(), 0.0);
  Mat<2> m2;
  m2 << 1, 2, 3, 4;
  EXPECT_EQ(transposed<2>(m2), Mat<2>(m2.transpose()));
}

// addTop() builds m's columns in registers (3D, AVX): each entry of the result's top rows must
// be the sum Eigen's topRows() += gives, bit for bit, and the fourth row stay zero.
TEST(Padded, AddTopIsTheTopRowsSumWithAZeroFourthRow) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  for (int trial = 0; trial < 20; ++trial) {
    Mat<3> a, m;
    for (int k = 0; k < 9; ++k) {
      a(k) = value(rng) * std::pow(10.0, trial % 7 - 3);
      m(k) = value(rng);
    }
    const PaddedMat<3> s = padded<3, 3>(a);
    PaddedMat<3> sum = PaddedMat<3>::Constant(-1.0);
    addTop<3>(s, m, sum);
    PaddedMat<3> expected = s;
    expected.topRows<3>() += m;
    for (int k = 0; k < 12; ++k)
      EXPECT_EQ(sum(k), expected(k)) << "entry " << k;  // bitwise: same operands, one addition
    EXPECT_EQ(sum.row(3).squaredNorm(), 0.0);
  }
  Mat<2> s2, m2, sum2;
  s2 << 1, 2, 3, 4;
  m2 << 0.5, 0.25, 0.125, 1.0 / 3.0;
  addTop<2>(s2, m2, sum2);
  EXPECT_TRUE(sum2 == Mat<2>(s2 + m2));
}

struct Case {
  double alpha;
  Quadrature quadrature;
  HourglassGradient penaltyGradient;
};

template <int D>
void expectForceIsMinusKu(const Case& c, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::array<int, D> counts;
  counts.fill(D == 2 ? 6 : 4);
  counts[0] = D == 2 ? 8 : 5;
  auto X = perturbedBlock<D>(counts, kDx, 0.15, rng);
  Scene<D> scene = sceneOf<D>(X, kDx, 2.4, testMaterial("linear-elastic"), c.alpha);
  scene.gradientCorrection = GradientCorrection::Quadratic;
  scene.quadrature = c.quadrature;
  scene.hourglassGradient = c.penaltyGradient;
  ForceEvaluator<D> eval(std::move(scene));
  const Index n = eval.size();
  std::vector<Vec<D>> u(n);
  const Mat<D> A = randomMatrix<D>(rng, 1e-3);
  for (Index i = 0; i < n; ++i) {
    const Vec<D>& Xi = eval.scene().particles.referencePosition[i];
    u[i] = A * Xi + Xi.squaredNorm() / kDx * randomVector<D>(rng, 1e-4) +
           randomVector<D>(rng, 1e-4 * kDx);
  }
  const auto f = eval.force(u);

  const auto& p = eval.scene().particles;
  DofMap<D> dofs(p, eval.scene().mirrorGhosts);
  ASSERT_EQ(dofs.size(), n);  // every particle free, in index order
  TangentStiffness<D> K(eval.reference(), eval.scene().materials, p.material, p.volume,
                        eval.scene().hourglass(), dofs, eval.scene().quadrature);
  K.update(eval.forces().deformationGradient());
  K.updateQuadrature(eval.forces().quadrature(), eval.forces().deformationGradient());
  Eigen::VectorXd v(D * n), Kv;
  for (Index i = 0; i < n; ++i)
    v.template segment<D>(D * i) = u[i];
  K.apply(v, Kv);

  double scale = 0.0, error = 0.0;
  for (Index i = 0; i < n; ++i) {
    scale = std::max(scale, f[i].cwiseAbs().maxCoeff());
    error = std::max(error, (f[i] + Kv.template segment<D>(D * i)).cwiseAbs().maxCoeff());
  }
  SCOPED_TRACE("D=" + std::to_string(D) + " alpha " + std::to_string(c.alpha) +
               (c.quadrature == Quadrature::Taylor ? " taylor" : " nodal") +
               (c.penaltyGradient == HourglassGradient::Linear ? " penalty on the linear F" : ""));
  EXPECT_GT(scale, 0.0);
  // two summation orders of the same linear map: rounding only
  EXPECT_LT(error, 1e-11 * scale);
}

TEST(Padded, ForcePassesGiveMinusTheUnpaddedTangentTimesU) {
  std::uint32_t seed = 1;
  for (auto quadrature : {Quadrature::Nodal, Quadrature::Taylor})
    for (auto gradient : {HourglassGradient::Corrected, HourglassGradient::Linear})
      for (double alpha : {0.0, 10.0}) {
        expectForceIsMinusKu<2>({alpha, quadrature, gradient}, seed++);
        expectForceIsMinusKu<3>({alpha, quadrature, gradient}, seed++);
      }
}

}  // namespace
