// Material library tests (docs/method.md section 4): every model in plane strain (2D, through the
// embedding helpers) and in 3D. P = dpsi/dF, a stress-free reference state, the small-strain
// limit, objectivity where claimed, constants conversions and validation messages.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <string>
#include <type_traits>
#include <variant>

#include "materials/Material.hpp"

namespace tlsph {
namespace {

using ::testing::HasSubstr;

constexpr double kYoung = 2.0e6;
constexpr double kPoisson = 0.3;
constexpr double kDensity = 1000.0;

ElasticConstants testConstants() {
  return ElasticConstants::fromYoungPoisson(kYoung, kPoisson);
}

template <int D>
using MatD = Eigen::Matrix<double, D, D>;

template <int D>
MatD<D> randomMatrix(std::mt19937& rng, double scale) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  MatD<D> G;
  for (int i = 0; i < D; ++i)
    for (int j = 0; j < D; ++j)
      G(i, j) = scale * unit(rng);
  return G;
}

// F = 1 + scale * random, redrawn until det F > minDet.
template <int D>
MatD<D> randomDeformation(std::mt19937& rng, double scale, double minDet = 0.5) {
  for (;;) {
    const MatD<D> F = MatD<D>::Identity() + randomMatrix<D>(rng, scale);
    if (F.determinant() > minDet) return F;
  }
}

template <int D>
MatD<D> randomRotation(std::mt19937& rng) {
  std::uniform_real_distribution<double> angle(-std::numbers::pi, std::numbers::pi);
  if constexpr (D == 2) {
    return Eigen::Rotation2Dd(angle(rng)).toRotationMatrix();
  } else {
    const Eigen::Vector3d axis = randomMatrix<3>(rng, 1.0).col(0).normalized();
    return Eigen::AngleAxisd(angle(rng), axis).toRotationMatrix();
  }
}

// sigma = lambda tr(eps) 1 + 2 mu eps (in 2D: the in-plane block of the plane-strain stress).
template <int D>
MatD<D> linearStress(const ElasticConstants& c, const MatD<D>& eps) {
  return c.lambda * eps.trace() * MatD<D>::Identity() + 2.0 * c.mu * eps;
}

// Central differences of psi: error O(h^2 psi''') + O(eps_machine psi / h). With F = O(1)
// entries, h = 1e-5 gives ~1e-10 truncation and ~1e-11 round-off relative to |P|.
constexpr double kFiniteDifferenceStep = 1e-5;

template <int D, class Model>
MatD<D> finiteDifferenceStress(const Model& model, const MatD<D>& F) {
  const double h = kFiniteDifferenceStep;
  MatD<D> P;
  for (int i = 0; i < D; ++i)
    for (int j = 0; j < D; ++j) {
      MatD<D> Fp = F, Fm = F;
      Fp(i, j) += h;
      Fm(i, j) -= h;
      P(i, j) = (strainEnergyDensity<D>(model, Fp) - strainEnergyDensity<D>(model, Fm)) / (2 * h);
    }
  return P;
}

// ---- Tangent modulus helpers ---------------------------------------------------------------

template <int D>
using TangentD = Eigen::Matrix<double, D * D, D * D>;
template <int D>
using VecD = Eigen::Matrix<double, D * D, 1>;

// M flattened in storage order, M(i, j) -> i + D j (the tangent modulus convention).
template <int D>
VecD<D> flatten(const MatD<D>& M) {
  return Eigen::Map<const VecD<D>>(M.data());
}
template <int D>
MatD<D> unflatten(const VecD<D>& v) {
  return Eigen::Map<const MatD<D>>(v.data());
}

// Frobenius norm of a tangent, by a plain loop: with -march=native, Eigen's fully unrolled
// AVX-512 reduction of a fixed 4 x 4 matrix trips a false GCC 12 -Wuninitialized inside the
// compiler's own intrinsics header.
template <class Derived>
double tangentNorm(const Eigen::MatrixBase<Derived>& A) {
  double sum = 0.0;
  for (Eigen::Index j = 0; j < A.cols(); ++j)
    for (Eigen::Index i = 0; i < A.rows(); ++i)
      sum += A(i, j) * A(i, j);
  return std::sqrt(sum);
}

// Central differences of P: column b is dP/dF_b. The step is 1e-6 relative to the largest
// |F_ij|; truncation O(h^2 |d3P/dF3|) ~ 1e-12 |A| and round-off ~ eps_machine |P| / h ~ 1e-10 |A|,
// far below the O(mu / |A|) ~ 1e-1 error that a wrong or missing term causes.
constexpr double kTangentStep = 1e-6;
constexpr double kTangentTolerance = 1e-6;  // on |A - A_fd| / |A|

template <int D, class Model>
TangentD<D> finiteDifferenceTangent(const Model& model, const MatD<D>& F) {
  const double h = kTangentStep * F.cwiseAbs().maxCoeff();
  TangentD<D> A;
  for (int b = 0; b < D * D; ++b) {
    MatD<D> Fp = F, Fm = F;
    Fp.data()[b] += h;
    Fm.data()[b] -= h;
    const MatD<D> dP = firstPiolaKirchhoff<D>(model, Fp) - firstPiolaKirchhoff<D>(model, Fm);
    A.col(b) = flatten<D>(dP) / (2 * h);
  }
  return A;
}

// max over `samples` random F = 1 + scale * random (det F > 0.3) of |A - A_fd| / |A|.
template <int D, class Model>
double maxTangentDiscrepancy(const Model& model, std::mt19937& rng, double scale, int samples) {
  double worst = 0.0;
  for (int sample = 0; sample < samples; ++sample) {
    const MatD<D> F = randomDeformation<D>(rng, scale, 0.3);
    const TangentD<D> A = tangentModulus<D>(model, F);
    const double error = tangentNorm(A - finiteDifferenceTangent<D>(model, F)) / tangentNorm(A);
    EXPECT_LT(error, kTangentTolerance) << "F =\n" << F;
    worst = std::max(worst, error);
  }
  return worst;
}

// ---- Typed over (model, dimension) ---------------------------------------------------------

template <class M, int Dim>
struct Case {
  using Model = M;
  static constexpr int D = Dim;
};

// "neo-hookean" + 3 -> "NeoHookean3D" ('-' would split a --gtest_filter pattern).
struct CaseName {
  template <class C>
  static std::string GetName(int) {
    std::string out;
    bool upper = true;
    for (const char ch : std::string_view(C::Model::name)) {
      if (ch == '-') {
        upper = true;
        continue;
      }
      out += upper ? static_cast<char>(std::toupper(static_cast<unsigned char>(ch))) : ch;
      upper = false;
    }
    return out + std::to_string(C::D) + "D";
  }
};

template <class C>
class MaterialModelTest : public ::testing::Test {
 protected:
  using Model = typename C::Model;
  static constexpr int D = C::D;
  using Mat = MatD<D>;

  MaterialModelTest() : model(testConstants(), kDensity) {}

  Model model;
  std::mt19937 rng{20240611};
};

using AllCases =
    ::testing::Types<Case<LinearElastic, 2>, Case<LinearElastic, 3>, Case<SaintVenantKirchhoff, 2>,
                     Case<SaintVenantKirchhoff, 3>, Case<NeoHookean, 2>, Case<NeoHookean, 3>,
                     Case<MooneyRivlin, 2>, Case<MooneyRivlin, 3>>;
TYPED_TEST_SUITE(MaterialModelTest, AllCases, CaseName);

TYPED_TEST(MaterialModelTest, StressIsEnergyGradientNearIdentity) {
  constexpr int D = TestFixture::D;
  for (int sample = 0; sample < 5; ++sample) {
    const auto F = randomDeformation<D>(this->rng, 0.05);
    const auto P = firstPiolaKirchhoff<D>(this->model, F);
    const auto Pfd = finiteDifferenceStress<D>(this->model, F);
    EXPECT_LT((P - Pfd).norm() / P.norm(), 1e-6) << "F =\n" << F;
  }
}

TYPED_TEST(MaterialModelTest, StressIsEnergyGradientAtLargeDeformation) {
  constexpr int D = TestFixture::D;
  for (int sample = 0; sample < 5; ++sample) {
    const auto F = randomDeformation<D>(this->rng, 0.3, 0.5);
    const auto P = firstPiolaKirchhoff<D>(this->model, F);
    const auto Pfd = finiteDifferenceStress<D>(this->model, F);
    EXPECT_LT((P - Pfd).norm() / P.norm(), 1e-6) << "F =\n" << F;
  }
}

TYPED_TEST(MaterialModelTest, TangentMatchesFiniteDifferencesNearIdentity) {
  constexpr int D = TestFixture::D;
  const double worst = maxTangentDiscrepancy<D>(this->model, this->rng, 0.05, 10);
  this->RecordProperty("max_relative_fd_discrepancy", ::testing::PrintToString(worst));
}

TYPED_TEST(MaterialModelTest, TangentMatchesFiniteDifferencesAtLargeDeformation) {
  constexpr int D = TestFixture::D;
  const double worst = maxTangentDiscrepancy<D>(this->model, this->rng, 0.3, 10);
  this->RecordProperty("max_relative_fd_discrepancy", ::testing::PrintToString(worst));
}

// A = d2 psi / dF dF is symmetric up to rounding (the FD check alone would allow 1e-6).
TYPED_TEST(MaterialModelTest, TangentHasMajorSymmetry) {
  constexpr int D = TestFixture::D;
  for (const double scale : {0.05, 0.3}) {
    for (int sample = 0; sample < 5; ++sample) {
      const auto F = randomDeformation<D>(this->rng, scale, 0.3);
      const TangentD<D> A = tangentModulus<D>(this->model, F);
      EXPECT_LE(tangentNorm(A - A.transpose()), 1e-14 * tangentNorm(A)) << "F =\n" << F;
    }
  }
}

// At F = 1 every model linearises to sigma(eps) = lambda tr(eps) 1 + 2 mu eps, and (stress-
// free reference) an infinitesimal rotation W = skew(G) gives no stress.
TYPED_TEST(MaterialModelTest, TangentAtIdentityIsLinearElasticity) {
  constexpr int D = TestFixture::D;
  using Mat = typename TestFixture::Mat;
  const TangentD<D> A = tangentModulus<D>(this->model, Mat(Mat::Identity()));
  for (int sample = 0; sample < 5; ++sample) {
    const Mat G = randomMatrix<D>(this->rng, 1e-3);
    const Mat eps = 0.5 * (G + G.transpose());
    const Mat W = 0.5 * (G - G.transpose());
    const Mat sigma = linearStress<D>(this->model.constants(), eps);
    const Mat dP = unflatten<D>(A * flatten<D>(eps));
    EXPECT_LE((dP - sigma).norm(), 1e-12 * sigma.norm()) << "dP =\n"
                                                         << dP << "\nsigma =\n"
                                                         << sigma;
    EXPECT_LE(unflatten<D>(A * flatten<D>(W)).norm(), 1e-12 * tangentNorm(A) * W.norm());
  }
}

TYPED_TEST(MaterialModelTest, ReferenceStateIsStressFreeWithZeroEnergy) {
  constexpr int D = TestFixture::D;
  using Mat = typename TestFixture::Mat;
  const Mat P = firstPiolaKirchhoff<D>(this->model, Mat::Identity());
  EXPECT_LE(P.cwiseAbs().maxCoeff(), 1e-14 * kYoung);
  EXPECT_NEAR(strainEnergyDensity<D>(this->model, Mat::Identity()), 0.0, 1e-14 * kYoung);
}

TYPED_TEST(MaterialModelTest, SmallStrainLimitIsLinearElasticity) {
  constexpr int D = TestFixture::D;
  using Mat = typename TestFixture::Mat;
  const double eps = 1e-6;
  for (int sample = 0; sample < 5; ++sample) {
    const Mat G = randomMatrix<D>(this->rng, 1.0);
    const Mat P = firstPiolaKirchhoff<D>(this->model, Mat(Mat::Identity() + eps * G));
    const Mat sigma =
        linearStress<D>(this->model.constants(), Mat(0.5 * eps * (G + G.transpose())));
    EXPECT_LT((P - sigma).norm() / sigma.norm(), 1e-4);
  }
}

// The `objective` flag is checked both ways: objective models satisfy P(QF) = Q P(F) and
// psi(QF) = psi(F); the linear model is not objective, and a rigid rotation stresses it.
TYPED_TEST(MaterialModelTest, ObjectivityMatchesTheFlag) {
  constexpr int D = TestFixture::D;
  using Model = typename TestFixture::Model;
  using Mat = typename TestFixture::Mat;
  if constexpr (Model::objective) {
    for (int sample = 0; sample < 5; ++sample) {
      const Mat F = randomDeformation<D>(this->rng, 0.3);
      const Mat Q = randomRotation<D>(this->rng);
      const Mat P = firstPiolaKirchhoff<D>(this->model, F);
      const Mat PQ = firstPiolaKirchhoff<D>(this->model, Mat(Q * F));
      EXPECT_LT((PQ - Q * P).norm() / P.norm(), 1e-12);
      const double psi = strainEnergyDensity<D>(this->model, F);
      const double psiQ = strainEnergyDensity<D>(this->model, Mat(Q * F));
      EXPECT_LT(std::abs(psiQ - psi) / psi, 1e-12);
    }
  } else {
    // Rigid rotation by 30 degrees: sym(Q - 1) = (cos 30deg - 1) in the rotation plane.
    const Mat Q = [] {
      if constexpr (D == 2)
        return Mat(Eigen::Rotation2Dd(std::numbers::pi / 6).toRotationMatrix());
      else
        return Mat(
            Eigen::AngleAxisd(std::numbers::pi / 6, Eigen::Vector3d::UnitZ()).toRotationMatrix());
    }();
    const Mat P = firstPiolaKirchhoff<D>(this->model, Q);
    EXPECT_GT(P.norm(), 0.05 * kYoung) << "a rigid rotation must stress the linear model";
    EXPECT_GT(strainEnergyDensity<D>(this->model, Q), 0.0);
    const Mat F = randomDeformation<D>(this->rng, 0.3);
    const Mat PQ = firstPiolaKirchhoff<D>(this->model, Mat(Q * F));
    const Mat QP = Q * firstPiolaKirchhoff<D>(this->model, F);
    EXPECT_GT((PQ - QP).norm(), 1e-3 * QP.norm());
  }
}

TYPED_TEST(MaterialModelTest, WaveSpeedFromPWaveModulus) {
  const ElasticConstants c = testConstants();
  const double expected = std::sqrt((c.lambda + 2 * c.mu) / kDensity);
  EXPECT_NEAR(this->model.waveSpeed(), expected, 1e-14 * expected);
  EXPECT_NEAR(waveSpeed(Material(this->model)), expected, 1e-14 * expected);
  EXPECT_EQ(density(Material(this->model)), kDensity);
}

TYPED_TEST(MaterialModelTest, RejectsInvalidDensity) {
  using Model = typename TestFixture::Model;
  for (const double rho : {0.0, -1.0, std::numeric_limits<double>::quiet_NaN(),
                           std::numeric_limits<double>::infinity()}) {
    try {
      Model m(testConstants(), rho);
      ADD_FAILURE() << "density " << rho << " accepted";
    } catch (const MaterialError& e) {
      EXPECT_THAT(e.what(), HasSubstr("density")) << e.what();
    }
  }
}

TYPED_TEST(MaterialModelTest, VariantEntryPointsAgreeWithTheModel) {
  constexpr int D = TestFixture::D;
  using Model = typename TestFixture::Model;
  using Mat = typename TestFixture::Mat;
  const Material material = makeMaterial(Model::name, testConstants(), kDensity);
  ASSERT_TRUE(std::holds_alternative<Model>(material));
  EXPECT_EQ(materialName(material), Model::name);
  EXPECT_EQ(elasticConstants(material).youngsModulus, kYoung);
  const Mat F = randomDeformation<D>(this->rng, 0.3);
  EXPECT_EQ(firstPiolaKirchhoff<D>(material, F), firstPiolaKirchhoff<D>(this->model, F));
  EXPECT_EQ(strainEnergyDensity<D>(material, F), strainEnergyDensity<D>(this->model, F));
  EXPECT_EQ(tangentModulus<D>(material, F), tangentModulus<D>(this->model, F));
}

// ---- Models undefined for det F <= 0 -------------------------------------------------------

template <class C>
class InvertedDeformationTest : public MaterialModelTest<C> {};

using LogarithmicCases = ::testing::Types<Case<NeoHookean, 2>, Case<NeoHookean, 3>,
                                          Case<MooneyRivlin, 2>, Case<MooneyRivlin, 3>>;
TYPED_TEST_SUITE(InvertedDeformationTest, LogarithmicCases, CaseName);

TYPED_TEST(InvertedDeformationTest, ReturnsNaNForNonPositiveJacobian) {
  constexpr int D = TestFixture::D;
  using Mat = typename TestFixture::Mat;
  Mat reflected = Mat::Identity();
  reflected(0, 0) = -1.0;  // det = -1
  Mat collapsed = Mat::Identity();
  collapsed(1, 1) = 0.0;  // det = 0
  Mat negativeRandom = randomDeformation<D>(this->rng, 0.3);
  negativeRandom.row(0) *= -1.0;  // det < 0
  for (const Mat& F : {reflected, collapsed, negativeRandom}) {
    const Mat P = firstPiolaKirchhoff<D>(this->model, F);
    EXPECT_TRUE(P.array().isNaN().all()) << "F =\n" << F << "\nP =\n" << P;
    EXPECT_TRUE(std::isnan(strainEnergyDensity<D>(this->model, F))) << "F =\n" << F;
    EXPECT_TRUE(tangentModulus<D>(this->model, F).array().isNaN().all()) << "F =\n" << F;
  }
}

// ---- Plane-strain embedding ----------------------------------------------------------------

TEST(PlaneStrain, EmbedsInPlaneDeformationWithUnitOutOfPlaneStretch) {
  Eigen::Matrix2d F;
  F << 1.1, 0.2, -0.3, 0.9;
  Eigen::Matrix3d expected;
  expected << 1.1, 0.2, 0.0, -0.3, 0.9, 0.0, 0.0, 0.0, 1.0;
  EXPECT_EQ(embedDeformationGradient<2>(F), expected);
  EXPECT_EQ(embedDeformationGradient<3>(expected), expected);
}

TEST(PlaneStrain, InPlaneStressIsTheBlockOfThe3DStress) {
  const NeoHookean model(testConstants(), kDensity);
  Eigen::Matrix2d F;
  F << 1.1, 0.2, -0.3, 0.9;
  const Eigen::Matrix3d P3 = model.firstPiolaKirchhoff(embedDeformationGradient<2>(F));
  EXPECT_EQ(firstPiolaKirchhoff<2>(model, F), (P3.topLeftCorner<2, 2>()));
  EXPECT_GT(std::abs(P3(2, 2)), 0.0);  // plane strain: out-of-plane stress is not zero
}

TEST(PlaneStrain, InPlaneTangentIsTheBlockOfThe3DTangent) {
  const MooneyRivlin model(testConstants(), kDensity);
  Eigen::Matrix2d F;
  F << 1.1, 0.2, -0.3, 0.9;
  const Eigen::Matrix<double, 9, 9> A3 = model.tangentModulus(embedDeformationGradient<2>(F));
  const Eigen::Matrix4d A2 = tangentModulus<2>(model, F);
  // 2D index i + 2 j <-> 3D index i + 3 j: F(0,0), F(1,0), F(0,1), F(1,1).
  const int inPlane[4] = {0, 1, 3, 4};
  for (int a = 0; a < 4; ++a)
    for (int b = 0; b < 4; ++b)
      EXPECT_EQ(A2(a, b), A3(inPlane[a], inPlane[b])) << "a = " << a << ", b = " << b;
}

// ---- Elastic constants ---------------------------------------------------------------------

// Moduli agree to 1e-12 of the largest modulus (lambda may be 0 or negative), nu to 1e-12.
void expectSameConstants(const ElasticConstants& a, const ElasticConstants& b) {
  const double scale = std::max({std::abs(a.lambda), a.mu, a.youngsModulus, a.bulkModulus});
  const double tol = 1e-12 * scale;
  EXPECT_NEAR(a.lambda, b.lambda, tol);
  EXPECT_NEAR(a.mu, b.mu, tol);
  EXPECT_NEAR(a.youngsModulus, b.youngsModulus, tol);
  EXPECT_NEAR(a.bulkModulus, b.bulkModulus, tol);
  EXPECT_NEAR(a.poissonRatio, b.poissonRatio, 1e-12);
}

TEST(ElasticConstants, ConversionsRoundTrip) {
  for (const double nu : {-0.9, -0.2, 0.0, 0.25, 0.3, 0.45, 0.499}) {
    SCOPED_TRACE("nu = " + std::to_string(nu));
    const auto fromEnu = ElasticConstants::fromYoungPoisson(kYoung, nu);
    const auto fromLame = ElasticConstants::fromLame(fromEnu.lambda, fromEnu.mu);
    const auto fromMuK = ElasticConstants::fromShearBulk(fromLame.mu, fromLame.bulkModulus);
    const auto back =
        ElasticConstants::fromYoungPoisson(fromMuK.youngsModulus, fromMuK.poissonRatio);
    expectSameConstants(fromEnu, fromLame);
    expectSameConstants(fromEnu, fromMuK);
    expectSameConstants(fromEnu, back);
    // The 3D isotropic relations themselves.
    EXPECT_NEAR(fromEnu.mu, kYoung / (2 * (1 + nu)), 1e-12 * fromEnu.mu);
    EXPECT_NEAR(fromEnu.bulkModulus, fromEnu.lambda + 2 * fromEnu.mu / 3,
                1e-12 * fromEnu.bulkModulus);
    EXPECT_DOUBLE_EQ(fromEnu.pWaveModulus(), fromEnu.lambda + 2 * fromEnu.mu);
  }
}

// Expects `make` to throw MaterialError whose message contains every one of `words`.
template <class Make>
void expectMaterialError(Make make, std::initializer_list<const char*> words) {
  try {
    make();
    ADD_FAILURE() << "no MaterialError thrown";
  } catch (const MaterialError& e) {
    for (const char* word : words)
      EXPECT_THAT(e.what(), HasSubstr(word));
  }
}

TEST(ElasticConstants, RejectsPoissonRatioOutsideRange) {
  for (const double nu : {0.5, -1.0, 0.7, -1.5}) {
    SCOPED_TRACE("nu = " + std::to_string(nu));
    expectMaterialError([&] { ElasticConstants::fromYoungPoisson(kYoung, nu); },
                        {"Poisson's ratio nu", "(-1, 0.5)"});
  }
  expectMaterialError([] { ElasticConstants::fromYoungPoisson(kYoung, 0.5); },
                      {"nu = 0.5 is outside the allowed range (-1, 0.5)"});
}

TEST(ElasticConstants, RejectsNonPositiveModuli) {
  expectMaterialError([] { ElasticConstants::fromYoungPoisson(-3.0, 0.3); },
                      {"Young's modulus E = -3 must be positive"});
  expectMaterialError([] { ElasticConstants::fromYoungPoisson(0.0, 0.3); },
                      {"Young's modulus E = 0"});
  expectMaterialError([] { ElasticConstants::fromLame(1.0e6, 0.0); }, {"shear modulus", "mu = 0"});
  expectMaterialError([] { ElasticConstants::fromLame(1.0e6, -2.0); }, {"mu = -2"});
  expectMaterialError([] { ElasticConstants::fromShearBulk(0.0, 1.0e6); },
                      {"shear modulus mu = 0 must be positive"});
  expectMaterialError([] { ElasticConstants::fromShearBulk(1.0e6, -1.0); },
                      {"bulk modulus K = -1 must be positive"});
  // Lame input whose implied K = lambda + 2 mu / 3 <= 0 (nu <= -1), at and beyond the edge.
  expectMaterialError([] { ElasticConstants::fromLame(-2.0e6, 1.5e6); },
                      {"lambda = -2000000", "bulk modulus K"});
  expectMaterialError([] { ElasticConstants::fromLame(-1.0e6, 1.5e6); },
                      {"lambda = -1000000", "bulk modulus K", "(-1, 0.5)"});
}

TEST(ElasticConstants, RejectsNonFiniteValues) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  expectMaterialError([&] { ElasticConstants::fromYoungPoisson(nan, 0.3); },
                      {"Young's modulus E = nan"});
  expectMaterialError([&] { ElasticConstants::fromYoungPoisson(inf, 0.3); },
                      {"Young's modulus E = inf"});
  expectMaterialError([&] { ElasticConstants::fromYoungPoisson(kYoung, nan); },
                      {"Poisson's ratio nu = nan"});
  expectMaterialError([&] { ElasticConstants::fromLame(nan, 1.0e6); }, {"lambda = nan"});
  expectMaterialError([&] { ElasticConstants::fromLame(1.0e6, inf); }, {"mu = inf"});
  expectMaterialError([&] { ElasticConstants::fromShearBulk(1.0e6, nan); }, {"bulk modulus K"});
  expectMaterialError([&] { validateDensity(nan); }, {"density"});
  expectMaterialError([&] { validateDensity(-1.0); }, {"density rho0 = -1 must be positive"});
}

TEST(ElasticConstants, ErrorIsAnInvalidArgument) {
  EXPECT_THROW(ElasticConstants::fromYoungPoisson(kYoung, 0.5), std::invalid_argument);
  EXPECT_NO_THROW(validateDensity(1.0));
}

// ---- Mooney-Rivlin split -------------------------------------------------------------------

TEST(MooneyRivlin, SplitsTheShearModulus) {
  const ElasticConstants c = testConstants();
  for (const double fraction : {0.0, 0.25, 0.5, 1.0}) {
    const MooneyRivlin model(c, kDensity, fraction);
    EXPECT_NEAR(model.c10() + model.c01(), c.mu / 2, 1e-15 * c.mu);
    EXPECT_NEAR(model.c01(), fraction * c.mu / 2, 1e-15 * c.mu);
  }
  EXPECT_EQ(MooneyRivlin(c, kDensity).c01(), MooneyRivlin(c, kDensity, 0.5).c01());
}

TEST(MooneyRivlin, EveryFractionHasTheSameSmallStrainLimitAndConsistentStress) {
  const ElasticConstants c = testConstants();
  std::mt19937 rng(7);
  for (const double fraction : {0.0, 0.25, 1.0}) {
    SCOPED_TRACE("c01Fraction = " + std::to_string(fraction));
    const MooneyRivlin model(c, kDensity, fraction);
    const Eigen::Matrix3d G = randomMatrix<3>(rng, 1.0);
    const Eigen::Matrix3d P = model.firstPiolaKirchhoff(Eigen::Matrix3d::Identity() + 1e-6 * G);
    const Eigen::Matrix3d sigma = linearStress<3>(c, Eigen::Matrix3d(0.5e-6 * (G + G.transpose())));
    EXPECT_LT((P - sigma).norm() / sigma.norm(), 1e-4);
    const Eigen::Matrix3d F = randomDeformation<3>(rng, 0.3);
    const Eigen::Matrix3d PF = model.firstPiolaKirchhoff(F);
    EXPECT_LT((PF - finiteDifferenceStress<3>(model, F)).norm() / PF.norm(), 1e-6);
  }
}

// The c10 and c01 terms separately: at the default fraction 0.5, c10 = c01, and a term with
// the two coefficients swapped would go almost unnoticed near J = 1.
TEST(MooneyRivlin, TangentMatchesFiniteDifferencesForEveryFraction) {
  const ElasticConstants c = testConstants();
  std::mt19937 rng(11);
  for (const double fraction : {0.0, 0.25, 1.0}) {
    SCOPED_TRACE("c01Fraction = " + std::to_string(fraction));
    const MooneyRivlin model(c, kDensity, fraction);
    maxTangentDiscrepancy<3>(model, rng, 0.3, 5);
    maxTangentDiscrepancy<2>(model, rng, 0.3, 5);
    const Eigen::Matrix<double, 9, 9> A = model.tangentModulus(randomDeformation<3>(rng, 0.3));
    EXPECT_LE((A - A.transpose()).norm(), 1e-14 * A.norm());
  }
}

TEST(MooneyRivlin, RejectsFractionOutsideUnitInterval) {
  for (const double fraction : {-0.1, 1.5, std::numeric_limits<double>::quiet_NaN()}) {
    SCOPED_TRACE("c01Fraction = " + std::to_string(fraction));
    expectMaterialError([&] { MooneyRivlin(testConstants(), kDensity, fraction); },
                        {"c01Fraction", "[0, 1]"});
  }
}

// ---- Names ---------------------------------------------------------------------------------

TEST(MaterialNames, ListsTheFourModels) {
  EXPECT_THAT(materialNames(), ::testing::ElementsAre("linear-elastic", "saint-venant-kirchhoff",
                                                      "neo-hookean", "mooney-rivlin"));
  for (const auto name : materialNames())
    EXPECT_EQ(materialName(makeMaterial(name, testConstants(), kDensity)), name);
}

TEST(MaterialNames, UnknownNameListsTheValidOnes) {
  expectMaterialError(
      [] { makeMaterial("hookean", testConstants(), kDensity); },
      {"'hookean'", "linear-elastic", "saint-venant-kirchhoff", "neo-hookean", "mooney-rivlin"});
}

TEST(MaterialNames, MakeMaterialValidatesDensity) {
  expectMaterialError([] { makeMaterial("neo-hookean", testConstants(), 0.0); }, {"density"});
}

}  // namespace
}  // namespace tlsph
