// The deformation gradient at a curved surface (method/DeformationGradient.hpp through the
// quadratic fit's gradient vectors), for the exact Lame field of a thick ring sampled at the
// particles of a gmsh mesh: what the particles' own strain can resolve, independently of any
// solve: the fit's own gradient vectors, without the integration constraint a mesh body has by
// default. Inside the body the fit sees neighbours all around; at the bore only on one side,
// with 7 to 12 neighbours for the 6 coefficients of a quadratic in 2D at support 2.1.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <string>

#include "method/PlainEvaluator.hpp"
#include "scene/Config.hpp"
#include "scene/SceneBuilder.hpp"

namespace tlsph::testing {
namespace {

// Relative errors of the particles' strains in the ring a <= r <= b (u(b) = 0, pressure p at
// the bore): at the bore nodes the hoop and radial strains, and inside (r >= a + 3 dx) the
// largest strain error relative to the bore's hoop strain.
struct SurfaceStrain {
  double hoopMean = 0.0, hoopScatter = 0.0;
  double radialMean = 0.0, radialScatter = 0.0, radialWorst = 0.0;
  double interiorWorst = 0.0;
  int boreNodes = 0;
};

SurfaceStrain lameRingStrain(double dx, double support) {
  const std::string text =
      "[scene]\ndimension = 2\ndx = " + std::to_string(dx) +
      "\n[material.steel]\nmodel = linear-elastic\ndensity = 7800\nyoungs_modulus = 2e11\n"
      "poisson_ratio = 0.3\n[body.ring]\nshape = mesh\nfile = " TLSPH_SOURCE_DIR
      "/validation/geometry/lame_ring.geo\n[kernel]\nintegration_constraint = false\nsupport = " +
      std::to_string(support) + "\n[time]\nend = 1\n[output]\nfields = none\n";
  PlainEvaluator<2> eval(buildScene<2>(Config::parse(text, "surface_strain.ini")).scene);
  const double E = 2e11, nu = 0.3, a = 0.05, b = 0.1, p = 1e8;
  const double lambda = E * nu / ((1 + nu) * (1 - 2 * nu)), mu = E / (2 * (1 + nu));
  const double B = p / (2 * (lambda + mu) / (b * b) + 2 * mu / (a * a)), A = -B / (b * b);
  const auto& X = eval.X();
  std::vector<Vec<2>> u(X.size());
  for (std::size_t i = 0; i < X.size(); ++i)
    u[i] = (A + B / X[i].squaredNorm()) * X[i];  // u_r = A r + B / r
  eval.force(u);
  const auto& F = eval.forces().deformationGradient();
  const double hoopAtBore = A + B / (a * a);
  SurfaceStrain s;
  double hoop2 = 0.0, radial2 = 0.0;
  for (std::size_t i = 0; i < X.size(); ++i) {
    const double r = X[i].norm();
    const Vec<2> n = X[i] / r, t(-n.y(), n.x());
    const Mat<2> eps = 0.5 * (F[i] + F[i].transpose()) - Mat<2>::Identity();
    const double hoop = A + B / (r * r), radial = A - B / (r * r);
    if (std::abs(r - a) < 1e-6 * a) {
      const double eh = t.dot(eps * t) / hoop - 1, er = n.dot(eps * n) / radial - 1;
      s.hoopMean += eh;
      hoop2 += eh * eh;
      s.radialMean += er;
      radial2 += er * er;
      s.radialWorst = std::max(s.radialWorst, std::abs(er));
      ++s.boreNodes;
    } else if (r > a + 3 * dx && r < b - 3 * dx) {
      const Mat<2> exact = hoop * t * t.transpose() + radial * n * n.transpose();
      s.interiorWorst = std::max(s.interiorWorst, (eps - exact).norm() / hoopAtBore);
    }
  }
  s.hoopMean /= s.boreNodes;
  s.radialMean /= s.boreNodes;
  s.hoopScatter = std::sqrt(hoop2 / s.boreNodes - s.hoopMean * s.hoopMean);
  s.radialScatter = std::sqrt(radial2 / s.boreNodes - s.radialMean * s.radialMean);
  std::cout << "dx " << dx << ", support " << support << ": " << s.boreNodes
            << " bore nodes, hoop strain " << 100 * s.hoopMean << " +- " << 100 * s.hoopScatter
            << " %, radial strain " << 100 * s.radialMean << " +- " << 100 * s.radialScatter
            << " % (worst " << 100 * s.radialWorst << " %); inside, worst " << 100 * s.interiorWorst
            << " % of the bore's hoop strain\n";
  return s;
}

// Inside, and along the surface (the hoop strain u_r / a at the bore), the strain is second
// order at either support. The radial strain at the bore, from the one-sided fit, is second
// order at support 2.5; at the default 2.1 its node-to-node scatter stays near 1 % (worst nodes
// 10 to 14 %, those with 7 to 9 neighbours) at every resolution tried, which is what limits the
// particles' own hoop stress at a loaded curved surface (docs/method.md, section 3.4).
TEST(SurfaceStrain, LameRingExactField) {
  for (double support : {2.1, 2.5}) {
    const SurfaceStrain coarse = lameRingStrain(0.003125, support);  // 16 through the wall
    const SurfaceStrain fine = lameRingStrain(0.0015625, support);   // 32
    EXPECT_LT(coarse.interiorWorst, 5e-3);
    EXPECT_LT(fine.interiorWorst, 0.5 * coarse.interiorWorst);
    EXPECT_LT(std::abs(coarse.hoopMean), 1e-2);
    EXPECT_LT(std::abs(fine.hoopMean), std::abs(coarse.hoopMean) / 3);  // h^2: 4
    EXPECT_LT(fine.hoopScatter, 1e-3);
    if (support == 2.5) {
      EXPECT_LT(std::abs(fine.radialMean), std::abs(coarse.radialMean) / 3);
      EXPECT_LT(fine.radialScatter, coarse.radialScatter / 2.5);
      EXPECT_LT(fine.radialWorst, 1e-2);
    }
  }
}

}  // namespace
}  // namespace tlsph::testing
