// The integration constraint (method/IntegrationConstraint.hpp) on mesh bodies: a uniform stress
// balances its own tractions at every particle, while F stays exact for quadratic fields and the
// force stays -dE/du.
#include <gtest/gtest.h>

#include <random>
#include <string>

#include "method/PlainEvaluator.hpp"
#include "scene/Config.hpp"
#include "scene/SceneBuilder.hpp"

namespace tlsph::testing {
namespace {

const std::string kData = TLSPH_SOURCE_DIR "/tests/geometry/data/";

// The 2D ring 1 <= r <= 2 or the 3D box with a hole, meshed at dx, steel, defaults otherwise.
template <int D>
Scene<D> meshScene(bool constrained, double dx, const std::string& quadrature = "taylor") {
  const std::string text =
      "[scene]\ndimension = " + std::to_string(D) + "\ndx = " + std::to_string(dx) +
      "\n[material.steel]\nmodel = linear-elastic\ndensity = 7800\n"
      "youngs_modulus = 2e11\npoisson_ratio = 0.3\n[body.part]\nshape = mesh\n"
      "file = " +
      kData + (D == 2 ? "ring.geo" : "box_hole.geo") + "\n[kernel]\nquadrature = " + quadrature +
      "\nintegration_constraint = " + (constrained ? "true" : "false") +
      "\n[time]\nend = 1\n[output]\nfields = none\n";
  return buildScene<D>(Config::parse(text, "integration_constraint.ini")).scene;
}

// max_I |f_I + P a_I| / max_I |P a_I| for the internal force of a uniform strain.
template <int D>
double uniformStressImbalance(PlainEvaluator<D>& eval, const std::vector<Vec<D>>& area) {
  const auto& X = eval.X();
  Mat<D> H = Mat<D>::Zero();
  H(0, 0) = 1e-4;
  H(1, 1) = -0.4e-4;
  H(0, 1) = 0.3e-4;
  H(D - 1, 0) += 0.2e-4;
  std::vector<Vec<D>> u(X.size());
  for (std::size_t i = 0; i < X.size(); ++i)
    u[i] = H * X[i];
  const auto f = eval.force(u);
  const double E = 2e11, nu = 0.3;
  const double lambda = E * nu / ((1 + nu) * (1 - 2 * nu)), mu = E / (2 * (1 + nu));
  const Mat<D> eps = 0.5 * (H + H.transpose());
  const Mat<D> P = lambda * eps.trace() * Mat<D>::Identity() + 2 * mu * eps;
  double scale = 0.0, worst = 0.0;
  for (std::size_t i = 0; i < X.size(); ++i)
    scale = std::max(scale, (P * area[i]).norm());
  for (std::size_t i = 0; i < X.size(); ++i)
    worst = worseOf(worst, (f[i] + P * area[i]).norm() / scale);
  return worst;
}

template <int D>
void checkUniformStressBalances(double dx, const std::string& quadrature) {
  PlainEvaluator<D> with(meshScene<D>(true, dx, quadrature));
  PlainEvaluator<D> without(meshScene<D>(false, dx, quadrature));
  const auto& area = with.scene().particles.boundaryArea;
  ASSERT_EQ(area.size(), std::size_t(with.size()));
  ASSERT_EQ(without.size(), with.size());  // the same mesh, the same particles
  const auto& summary = with.reference().integrationConstraint;
  EXPECT_TRUE(summary.applied);
  EXPECT_FALSE(without.reference().integrationConstraint.applied);
  // Without the correction the defect is of the order of a surface particle's own area vector;
  // with it, what is left is the O(h^2) part no correction can remove.
  const double before = uniformStressImbalance<D>(without, area);
  const double after = uniformStressImbalance<D>(with, area);
  EXPECT_GT(before, 0.05);
  EXPECT_LT(after, 1e-3 * before) << "before " << before << ", solve " << summary.iterations
                                  << " iterations, defect " << summary.defectAfter;
  // The Cholesky factor of the shifted matrix is the operator's inverse but for its few
  // smallest eigenvalues: a wrongly assembled matrix would show as many iterations.
  EXPECT_TRUE(summary.factorised);
  EXPECT_LE(summary.iterations, 20);
}

template <int D>
void checkQuadraticFieldsStayExact(double dx) {
  PlainEvaluator<D> eval(meshScene<D>(true, dx));
  const auto& X = eval.X();
  std::mt19937 rng(7);
  const Vec<D> b = randomVector<D>(rng, 1e-3);
  const Mat<D> A = randomMatrix<D>(rng, 1e-3);
  std::vector<Vec<D>> u(X.size());
  std::vector<Mat<D>> grad(X.size());
  for (std::size_t i = 0; i < X.size(); ++i) {
    // u = b + A X + 1/2 c (X . X) e_0: its gradient A + c e_0 X^T
    const double c = 2e-3;
    u[i] = b + A * X[i];
    u[i][0] += 0.5 * c * X[i].squaredNorm();
    grad[i] = A;
    grad[i].row(0) += c * X[i].transpose();
  }
  eval.force(u);
  std::vector<std::uint8_t> fallback(X.size(), 0);
  for (Index i : eval.reference().linearFallback)
    fallback[i] = 1;
  double worst = 0.0;
  for (std::size_t i = 0; i < X.size(); ++i)
    if (!fallback[i])
      worst = worseOf(
          worst, (eval.forces().deformationGradient()[i] - Mat<D>::Identity() - grad[i]).norm() /
                     grad[i].norm());
  EXPECT_LT(worst, 1e-9);
}

template <int D>
void checkForceIsMinusEnergyGradient(double dx) {
  PlainEvaluator<D> eval(meshScene<D>(true, dx));
  std::mt19937 rng(11);
  std::vector<Vec<D>> u(eval.size());
  for (auto& ui : u)
    ui = randomVector<D>(rng, 1e-4 * dx);
  double fmax = 0.0;
  const double error = energyGradientError<D>(eval, u, 1e-7 * dx, fmax);
  EXPECT_LT(error, 1e-6 * fmax);
  Vec<D> total = Vec<D>::Zero();
  for (const auto& fi : eval.force(u))
    total += fi;
  EXPECT_LT(total.norm(), 1e-10 * fmax * eval.size());
}

// The run's fused passes read the corrected vectors like the plain loops.
template <int D>
void checkFastPassAgrees(double dx) {
  PlainEvaluator<D> plain(meshScene<D>(true, dx));
  ForceEvaluator<D> fast(meshScene<D>(true, dx));
  std::mt19937 rng(5);
  std::vector<Vec<D>> u(plain.size());
  for (auto& ui : u)
    ui = randomVector<D>(rng, 1e-3 * dx);
  const auto a = plain.force(u), b = fast.force(u);
  double scale = 0.0, worst = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i)
    scale = std::max(scale, a[i].norm());
  for (std::size_t i = 0; i < a.size(); ++i)
    worst = worseOf(worst, (a[i] - b[i]).norm() / scale);
  EXPECT_LT(worst, 1e-10);
}

}  // namespace

TEST(IntegrationConstraint, FastPassAgrees2D) {
  checkFastPassAgrees<2>(0.25);
}
TEST(IntegrationConstraint, FastPassAgrees3D) {
  checkFastPassAgrees<3>(0.5);
}
TEST(IntegrationConstraint, UniformStressBalancesItsTractions2D) {
  checkUniformStressBalances<2>(0.25, "taylor");
}
TEST(IntegrationConstraint, UniformStressBalancesItsTractions2DNodal) {
  checkUniformStressBalances<2>(0.25, "nodal");
}
TEST(IntegrationConstraint, UniformStressBalancesItsTractions3D) {
  checkUniformStressBalances<3>(0.5, "taylor");
}
TEST(IntegrationConstraint, QuadraticFieldsStayExact2D) {
  checkQuadraticFieldsStayExact<2>(0.25);
}
TEST(IntegrationConstraint, QuadraticFieldsStayExact3D) {
  checkQuadraticFieldsStayExact<3>(0.5);
}
TEST(IntegrationConstraint, ForceIsMinusEnergyGradient2D) {
  checkForceIsMinusEnergyGradient<2>(0.25);
}
TEST(IntegrationConstraint, ForceIsMinusEnergyGradient3D) {
  checkForceIsMinusEnergyGradient<3>(0.5);
}

}  // namespace tlsph::testing
