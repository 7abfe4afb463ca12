// The inertia count (Inertia): the number of negative entries of D in L D L^T of K - sigma M is
// the number of eigenvalues of (K, M) below sigma. Checked against every eigenvalue computed
// densely (Eigen's GeneralizedSelfAdjointEigenSolver on the dense K and M) at shifts between
// consecutive distinct eigenvalues across the whole spectrum, for a free body (zero modes,
// penalty, Taylor quadrature), a free body with spurious zero modes (no penalty, linear
// correction, nodal quadrature on a periodic lattice) and a clamped one.
#include <gtest/gtest.h>

#include <Eigen/Dense>

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

}  // namespace
