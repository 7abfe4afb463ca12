// The inertia count (Inertia): the number of negative entries of D in L D L^T of K - sigma M is
// the number of eigenvalues of (K, M) below sigma. Checked against every eigenvalue computed
// densely (Eigen's GeneralizedSelfAdjointEigenSolver on the dense K and M) at shifts between
// consecutive distinct eigenvalues across the whole spectrum, for a free body (zero modes,
// penalty, Taylor quadrature), a free body with spurious zero modes (no penalty, linear
// correction, nodal quadrature on a periodic lattice) and a clamped one; and on a matrix large
// enough for many supernodes, a grid Laplacian whose eigenvalues are known in closed form.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <vector>

#include "ModesTestScenes.hpp"
#include "TestSupport.hpp"
#include "modes/ExactStiffness.hpp"
#include "modes/Inertia.hpp"

using namespace tlsph;
using namespace tlsph::testing;

namespace {

// Returns the count below 1e-10 of the largest eigenvalue: the zero modes.
template <int D>
long expectCountsMatchSpectrum(Scene<D> scene, const std::string& what) {
  TangentAt<D> t(scene);
  const ExactStiffness e =
      exactStiffness(t.K, t.solver.reference(), t.dofs, scene.hourglass().enabled(), 100'000'000);
  if (!e.made) {
    ADD_FAILURE() << what << ": " << e.reason;
    return -1;
  }
  const Eigen::MatrixXd lower = Eigen::MatrixXd(e.lower);
  const Eigen::MatrixXd K = lower.template selfadjointView<Eigen::Lower>();
  const Eigen::MatrixXd M = t.mass.asDiagonal();
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> dense(K, M, Eigen::EigenvaluesOnly);
  EXPECT_EQ(dense.info(), Eigen::Success);
  const Eigen::VectorXd lambda = dense.eigenvalues();  // ascending
  const double scale = lambda[lambda.size() - 1];
  Inertia inertia(e.lower, t.mass);
  int shifts = 0;
  // below everything, above everything, and between every pair of distinct neighbours
  EXPECT_EQ(inertia.countBelow(lambda[0] - 1e-6 * scale), 0) << what;
  EXPECT_EQ(inertia.countBelow(1.01 * scale), lambda.size()) << what;
  for (Eigen::Index k = 0; k + 1 < lambda.size(); ++k) {
    const double gap = lambda[k + 1] - lambda[k];
    if (gap < 1e-6 * std::max(std::abs(lambda[k + 1]), 1e-6 * scale)) continue;
    const double sigma = lambda[k] + 0.5 * gap;
    EXPECT_EQ(inertia.countBelow(sigma), k + 1) << what << ": sigma " << sigma;
    ++shifts;
  }
  std::cout << what << ": " << lambda.size() << " eigenvalues, " << shifts
            << " shifts checked, L D L^T " << inertia.factorNonZeros() << " entries\n";
  // (a symmetric lattice has few distinct eigenvalues)
  EXPECT_GE(shifts, 10) << what;
  return inertia.countBelow(1e-10 * scale);
}

TEST(Inertia, CountsMatchTheDenseSpectrumOfAFreeBody2D) {
  EXPECT_EQ(expectCountsMatchSpectrum<2>(setupOf<2>(bodyText<2>(Shape::Polygon, {})).scene,
                                         "2D polygon, quadratic taylor, penalty"),
            3);
}

TEST(Inertia, CountsMatchTheDenseSpectrumOfAFreeBody3D) {
  EXPECT_EQ(expectCountsMatchSpectrum<3>(setupOf<3>(bodyText<3>(Shape::Box, {})).scene,
                                         "3D box, quadratic taylor, penalty"),
            6);
}

TEST(Inertia, CountsMatchTheDenseSpectrumWithSpuriousZeros) {
  // the periodic lattice without the penalty: 8 zero modes, 2 of them translations
  constexpr double dx = 0.01;
  Scene<2> scene = sceneOf<2>(cellCentredLattice<2>(Vec<2>::Zero(), {8, 8}, dx), dx, 2.0,
                              testMaterial("linear-elastic"), 0.0);
  scene.periodicBox.periodic.fill(true);
  scene.periodicBox.length = Vec<2>::Constant(8 * dx);
  EXPECT_EQ(expectCountsMatchSpectrum<2>(scene, "2D periodic lattice, linear nodal, no penalty"),
            8);
}

TEST(Inertia, CountsMatchTheDenseSpectrumOfAClampedBody) {
  EXPECT_EQ(expectCountsMatchSpectrum<3>(
                setupOf<3>(bodyText<3>(Shape::Box, {"linear", "nodal", 10.0}, "clamp")).scene,
                "3D box clamped, linear nodal, penalty"),
            0);
}

// The 7-point Laplacian on an n x n x n grid with zero values outside, M = h^3 1 (lumped), has
// the eigenvalues (1/h^2) sum_d (2 - 2 cos(pi k_d / (n + 1))), k_d = 1..n: every count is known
// without a dense solve, at a size (n = 14: 2,744 unknowns, a factor of about a million
// entries) where the elimination passes through many supernodes and their Schur complements.
TEST(Inertia, CountsMatchTheClosedFormSpectrumOfAGridLaplacian) {
  constexpr int n = 14;
  const double h = 1.0 / (n + 1);
  const int size = n * n * n;
  auto index = [&](int i, int j, int k) { return (k * n + j) * n + i; };
  std::vector<Eigen::Triplet<double>> lower;
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const int c = index(i, j, k);
        lower.emplace_back(c, c, 6.0 / (h * h) * h * h * h);
        if (i + 1 < n) lower.emplace_back(index(i + 1, j, k), c, -h);
        if (j + 1 < n) lower.emplace_back(index(i, j + 1, k), c, -h);
        if (k + 1 < n) lower.emplace_back(index(i, j, k + 1), c, -h);
      }
  Inertia::Matrix K(size, size);
  K.setFromTriplets(lower.begin(), lower.end());
  const Eigen::VectorXd mass = Eigen::VectorXd::Constant(size, h * h * h);

  std::vector<double> oneD(n), lambda;
  for (int k = 1; k <= n; ++k)
    oneD[k - 1] = (2.0 - 2.0 * std::cos(M_PI * k / (n + 1))) / (h * h);
  for (double a : oneD)
    for (double b : oneD)
      for (double c : oneD)
        lambda.push_back(a + b + c);
  std::sort(lambda.begin(), lambda.end());

  Inertia inertia(K, mass);
  EXPECT_GT(inertia.factorNonZeros(), 20L * size);  // fill-in: far from a banded toy
  int shifts = 0;
  for (std::size_t k = 0; k + 1 < lambda.size(); k += 97) {
    // the first shift between two distinct eigenvalues at or after k
    std::size_t m = k;
    while (m + 1 < lambda.size() && lambda[m + 1] - lambda[m] < 1e-6 * lambda.back())
      ++m;
    if (m + 1 >= lambda.size()) break;
    const double sigma = 0.5 * (lambda[m] + lambda[m + 1]);
    EXPECT_EQ(inertia.countBelow(sigma), static_cast<long>(m + 1)) << "sigma " << sigma;
    ++shifts;
  }
  EXPECT_GE(shifts, 25);
  EXPECT_EQ(inertia.countBelow(0.5 * lambda.front()), 0);
  EXPECT_EQ(inertia.countBelow(2.0 * lambda.back()), size);
}

}  // namespace
