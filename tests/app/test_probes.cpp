// Probes: a kernel probe carries each particle's displacement to the probe point with its
// deformation gradient, so it is exact for affine fields, also at a surface point outside the
// particle cloud's hull (a beam tip); a nearest probe reports the nearest particle's value; a
// surface probe recovers the stress from its surface and the traction of the loads on it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "app/RunSeries.hpp"
#include "scene/Config.hpp"
#include "scene/SceneBuilder.hpp"

using namespace tlsph;

namespace {

const std::string kBeam = R"(
[scene]
dimension = 2
dx = 0.01
[material.m]
model = neo-hookean
density = 1000
youngs_modulus = 1e6
poisson_ratio = 0.3
[body.bar]
shape = box
lower = 0 0
upper = 0.2 0.04
[time]
end = 0.01
[probe.tip]
point = 0.2 0.02
method = kernel
quantities = displacement velocity cauchy_stress
[probe.corner]
point = 0.2 0.04
method = kernel
[probe.near]
point = 0.2 0.02
method = nearest
)";

// The value of a probes.csv column in a row.
double columnValue(const std::vector<std::string>& columns, const std::vector<double>& row,
                   const std::string& column) {
  const auto at = std::find(columns.begin(), columns.end(), column);
  EXPECT_NE(at, columns.end()) << column;
  return at == columns.end() ? std::nan("") : row[at - columns.begin()];
}

}  // namespace

TEST(Probes, KernelProbeIsExactForAffineFieldsAtSurfacePoints) {
  SceneSetup<2> setup = buildScene<2>(Config::parse(kBeam, "beam.ini"));
  Mat<2> G;
  G << 0.03, -0.2, 0.11, 0.05;
  const Vec<2> c(0.001, -0.002);
  auto& p = setup.scene.particles;
  for (Index i = 0; i < p.size(); ++i) {
    p.displacement[i] = c + G * p.referencePosition[i];
    p.velocity[i] = Vec<2>(1.0, 2.0);
  }
  Solver<2> solver(setup.scene, setup.solver);  // computes F for the current displacement
  const auto row = probeRow(setup, solver);
  const auto columns = probeColumns(setup);
  ASSERT_EQ(row.size(), columns.size());
  auto value = [&](const std::string& column) { return columnValue(columns, row, column); };
  const Vec<2> tip = c + G * Vec<2>(0.2, 0.02), corner = c + G * Vec<2>(0.2, 0.04);
  EXPECT_NEAR(value("tip_ux"), tip.x(), 1e-14);
  EXPECT_NEAR(value("tip_uy"), tip.y(), 1e-14);
  EXPECT_NEAR(value("corner_ux"), corner.x(), 1e-14);
  EXPECT_NEAR(value("corner_uy"), corner.y(), 1e-14);
  EXPECT_NEAR(value("tip_vx"), 1.0, 1e-14);  // velocities: Shepard average
  EXPECT_NEAR(value("tip_vy"), 2.0, 1e-14);
  // The nearest particles to (0.2, 0.02) sit half a spacing inside the tip, at (0.195, 0.015)
  // and (0.195, 0.025), equally near: the probe takes the first in the lattice's order (lower y),
  // whatever the numbering, and reports its own value, not the tip's.
  const Vec<2> a = c + G * Vec<2>(0.195, 0.015);
  EXPECT_NEAR(value("near_ux"), a.x(), 1e-14);
  EXPECT_NEAR(value("near_uy"), a.y(), 1e-14);
  const Index near = setup.probes.back().particles.front();
  EXPECT_LT((p.referencePosition[near] - Vec<2>(0.195, 0.015)).norm(), 1e-12) << near;

  // A homogeneous deformation: every particle has the same F up to the rounding of its
  // gradient vectors (the corrected fit reproduces an affine field to about 1e-13 here), so the
  // stress probe, a weighted mean of the particles' stresses (Shepard: positive weights summing
  // to one), is the material's Cauchy stress for that F within the largest particle's deviation
  // from it (plane strain: sigma_zz included, no xz, yz).
  const Mat<2> Fexact = Mat<2>::Identity() + G;
  const Mat3 F3 = embedDeformationGradient<2>(Fexact);
  const Mat3 P = std::visit([&](const auto& m) { return m.firstPiolaKirchhoff(F3); },
                            setup.scene.materials[0]);
  const Mat3 sigma = P * F3.transpose() / F3.determinant();
  const double scale = sigma.norm();
  const auto& tipProbe = setup.probes.front();
  ASSERT_EQ(tipProbe.name, "tip");
  double weightSum = 0.0, deviation = 0.0;
  for (std::size_t k = 0; k < tipProbe.particles.size(); ++k) {
    const Index j = tipProbe.particles[k];
    EXPECT_GT(tipProbe.weights[k], 0.0);
    weightSum += tipProbe.weights[k];
    const Mat<2>& Fj = solver.forces().deformationGradient()[j];
    EXPECT_LT((Fj - Fexact).cwiseAbs().maxCoeff(), 1e-12) << j;  // the patch test's F
    deviation = std::max(deviation, (cauchyStressOf(setup, Fj, j) - sigma).cwiseAbs().maxCoeff());
  }
  EXPECT_NEAR(weightSum, 1.0, 1e-14);
  EXPECT_LT(deviation, 1e-10 * scale);  // what F's rounding can make of the stress
  const double bound = deviation + 1e-14 * scale;
  EXPECT_NEAR(value("tip_sxx"), sigma(0, 0), bound);
  EXPECT_NEAR(value("tip_syy"), sigma(1, 1), bound);
  EXPECT_NEAR(value("tip_szz"), sigma(2, 2), bound);
  EXPECT_NEAR(value("tip_sxy"), sigma(0, 1), bound);
  EXPECT_NEAR(value("tip_syz"), 0.0, bound);
  EXPECT_NEAR(value("tip_sxz"), 0.0, bound);
  EXPECT_GT(std::abs(sigma(2, 2)), 1e-3 * scale);
}

// A surface probe on the Lame ring's bore under a pressure p: for the uniform in-plane strain
// whose stress is -p 1 in the plane (in equilibrium with that pressure on every surface), it
// reads sigma = -p 1 from the surface's displacements and the load's traction, and reports the
// particle's own displacement. A wrong traction (sign, area, ramp) would change its normal part.
TEST(Probes, SurfaceProbeRecoversTheStressFromTheLoadsTraction) {
  const std::string text = R"(
[scene]
dimension = 2
dx = 0.00625
[material.steel]
model = linear-elastic
density = 7800
youngs_modulus = 2e11
poisson_ratio = 0.3
[body.ring]
shape = mesh
file = )" TLSPH_SOURCE_DIR R"(/validation/geometry/lame_ring.geo
[load.p]
surface = bore
type = pressure
value = 1e8
[time]
end = 1
[probe.s]
point = 0.03 0.04
method = surface
surface = bore
quantities = displacement cauchy_stress
)";
  SceneSetup<2> setup = buildScene<2>(Config::parse(text, "ring.ini"));
  const double E = 2e11, nu = 0.3, p = 1e8;
  const double lambda = E * nu / ((1 + nu) * (1 - 2 * nu)), mu = E / (2 * (1 + nu));
  const double e = -p / (2 * (lambda + mu));
  auto& particles = setup.scene.particles;
  for (Index i = 0; i < particles.size(); ++i)
    particles.displacement[i] = e * particles.referencePosition[i];
  Solver<2> solver(setup.scene, setup.solver);
  const auto row = probeRow(setup, solver);
  const auto columns = probeColumns(setup);
  auto value = [&](const std::string& column) { return columnValue(columns, row, column); };
  const Probe<2>& probe = setup.probes.front();
  const Index i = probe.particles.front();
  EXPECT_NEAR(particles.referencePosition[i].norm(), 0.05, 1e-12);  // a bore node
  EXPECT_LT((particles.referencePosition[i] - Vec<2>(0.03, 0.04)).norm(), 0.00625);
  EXPECT_EQ(value("s_ux"), particles.displacement[i].x());
  // The material's P (small strain: P = -p 1 in the plane), as the Cauchy stress P F^T / J.
  const Mat3 sigma = cauchyStressOf(setup, Mat<2>((1 + e) * Mat<2>::Identity()), i);
  EXPECT_NEAR(sigma(0, 0), -p * (1 - e), 1e-6 * p);
  EXPECT_NEAR(value("s_sxx"), sigma(0, 0), 1e-9 * p);
  EXPECT_NEAR(value("s_syy"), sigma(1, 1), 1e-9 * p);
  EXPECT_NEAR(value("s_sxy"), 0.0, 1e-9 * p);
  EXPECT_NEAR(value("s_szz"), sigma(2, 2), 1e-9 * p);
  EXPECT_NEAR(sigma(2, 2), 2 * lambda * e, 1e-3 * p);
}
