// The stress recovered at a loaded surface (method/SurfaceStress.hpp) on the bore of the Lame
// ring and cylinder meshed by gmsh: exact for affine fields with their own traction (dead or
// following), and second order for the exact Lame field with the bore's pressure, at every
// bore node, where the particles' own strain is not (tests/method/test_surface_strain.cpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <string>

#include "materials/Material.hpp"
#include "method/SurfaceStress.hpp"
#include "scene/Config.hpp"
#include "scene/SceneBuilder.hpp"

namespace tlsph::testing {
namespace {

template <int D>
SceneSetup<D> lameBody(double dx, const std::string& model) {
  const std::string geometry = D == 2 ? "lame_ring.geo" : "lame_cylinder.geo";
  const std::string text =
      "[scene]\ndimension = " + std::to_string(D) + "\ndx = " + std::to_string(dx) +
      "\n[material.steel]\nmodel = " + model +
      "\ndensity = 7800\nyoungs_modulus = 2e11\npoisson_ratio = 0.3\n[body.ring]\nshape = "
      "mesh\nfile = " TLSPH_SOURCE_DIR "/validation/geometry/" +
      geometry + "\n[time]\nend = 1\n[output]\nfields = none\n";
  return buildScene<D>(Config::parse(text, "surface_stress.ini"));
}

template <int D>
std::vector<SurfaceStencil<D>> boreStencils(const SceneSetup<D>& setup) {
  const SurfacePatch<D>& bore = setup.surfaces.at("bore");
  std::vector<SurfaceStencil<D>> out;
  for (std::size_t k = 0; k < bore.particles.size(); ++k) {
    std::string why;
    auto s = surfaceStencil<D>(bore.particles[k], setup.scene.particles.referencePosition,
                               bore.particles, bore.areaVector, bore.areaVector[k],
                               setup.scene.supportRadius, why);
    EXPECT_TRUE(s.has_value()) << why;
    if (s) out.push_back(*s);
  }
  return out;
}

// u = G X with the traction P(1 + G) N on the bore: the recovered gradient is G at every bore
// node, for a linear and a nonlinear material (Newton on the traction condition).
template <int D>
void affineIsExact(const std::string& model, double dx) {
  const auto setup = lameBody<D>(dx, model);
  const auto& X = setup.scene.particles.referencePosition;
  const Material& material = setup.scene.materials[0];
  Mat<D> G;
  if constexpr (D == 2)
    G << 2e-3, -7e-4, 1.1e-3, -1.5e-3;
  else
    G << 2e-3, -7e-4, 3e-4, 1.1e-3, -1.5e-3, 6e-4, -4e-4, 9e-4, 1.2e-3;
  if (model != "linear-elastic") G *= 50.0;  // strains of several per cent
  std::vector<Vec<D>> u(X.size());
  for (std::size_t i = 0; i < X.size(); ++i)
    u[i] = G * X[i];
  const Mat<D> P = firstPiolaKirchhoff<D>(material, Mat<D>(Mat<D>::Identity() + G));
  double worst = 0.0;
  for (const auto& s : boreStencils<D>(setup)) {
    const Mat<D> H =
        recoveredDisplacementGradient<D>(s, u, material, P * s.normal, 0.0, Mat<D>::Zero());
    worst = std::max(worst, (H - G).norm() / G.norm());
  }
  EXPECT_LT(worst, 1e-9) << model << " in " << D << "D";
}

TEST(SurfaceStress, AffineFieldWithItsTractionIsExact) {
  affineIsExact<2>("linear-elastic", 0.00625);
  affineIsExact<2>("neo-hookean", 0.00625);
  affineIsExact<3>("linear-elastic", 0.0125);
  affineIsExact<3>("neo-hookean", 0.0125);
}

// A uniform stretch F = s 1 of a neo-Hookean body is in equilibrium with the following pressure
// p = -sigma_nn on its surface: the recovery, given only p, finds F again.
TEST(SurfaceStress, UniformStretchUnderFollowingPressureIsExact) {
  const auto setup = lameBody<2>(0.00625, "neo-hookean");
  const auto& X = setup.scene.particles.referencePosition;
  const Material& material = setup.scene.materials[0];
  const double stretch = 0.97;
  std::vector<Vec<2>> u(X.size());
  for (std::size_t i = 0; i < X.size(); ++i)
    u[i] = (stretch - 1.0) * X[i];
  const Mat<2> F = stretch * Mat<2>::Identity();
  const Mat<2> sigma = firstPiolaKirchhoff<2>(material, F) * F.transpose() / F.determinant();
  const double p = -sigma(0, 0);
  ASSERT_GT(p, 0.0);
  double worst = 0.0;
  for (const auto& s : boreStencils<2>(setup)) {
    const Mat<2> H =
        recoveredDisplacementGradient<2>(s, u, material, Vec<2>::Zero(), p, Mat<2>::Zero());
    worst = std::max(worst, (H - (F - Mat<2>::Identity())).norm() / (1.0 - stretch));
  }
  EXPECT_LT(worst, 1e-9);
}

// The exact Lame field (plane strain, u(b) = 0, pressure p at the bore) sampled at the
// particles, the bore's pressure as the dead traction -p N: the recovered hoop stress at every
// bore node, relative to the exact one. On the bore u = u_r(a) n, whose tangential derivative
// the fit resolves exactly on the 2D ring's evenly spaced bore nodes, so there the recovery is
// exact up to rounding;
// the particles' own F reads it with a scatter of 3 % and worst nodes of 10-23 % at support
// 2.1 (test_surface_strain.cpp).
template <int D>
double lameHoopStressWorst(double dx) {
  const auto setup = lameBody<D>(dx, "linear-elastic");
  const auto& X = setup.scene.particles.referencePosition;
  const Material& material = setup.scene.materials[0];
  const double E = 2e11, nu = 0.3, a = 0.05, b = 0.1, p = 1e8;
  const double lambda = E * nu / ((1 + nu) * (1 - 2 * nu)), mu = E / (2 * (1 + nu));
  const double B = p / (2 * (lambda + mu) / (b * b) + 2 * mu / (a * a)), A = -B / (b * b);
  const double exact = 2 * (lambda + mu) * A + 2 * mu * B / (a * a);
  std::vector<Vec<D>> u(X.size(), Vec<D>::Zero());
  for (std::size_t i = 0; i < X.size(); ++i) {
    const Vec<2> R = X[i].template head<2>();
    u[i].template head<2>() = (A + B / R.squaredNorm()) * R;  // u_r = A r + B / r, u_z = 0
  }
  double worst = 0.0;
  for (const auto& s : boreStencils<D>(setup)) {
    const Mat<D> H =
        recoveredDisplacementGradient<D>(s, u, material, -p * s.normal, 0.0, Mat<D>::Zero());
    const Mat<D> P = firstPiolaKirchhoff<D>(material, Mat<D>(Mat<D>::Identity() + H));
    Vec<D> hoop = Vec<D>::Zero();  // the bore's axis is z
    hoop.template head<2>() = Vec<2>(-s.normal[1], s.normal[0]);
    worst = std::max(worst, std::abs(hoop.dot(P * hoop) / exact - 1.0));
  }
  return worst;
}

TEST(SurfaceStress, LameFieldAtTheBoreIsRecovered) {
  EXPECT_LT(lameHoopStressWorst<2>(0.05 / 16), 1e-8);
  // In 3D the bore's triangles are unstructured: the fit's O(h^2) error, 0.25 % at 8 through.
  EXPECT_LT(lameHoopStressWorst<3>(0.05 / 8), 0.005);
}

// A field that varies along the surface, u = eps (sin(y / l + 0.3), cos(x / l), sin((x + z) / l)),
// with its own traction P(1 + grad u) N at each bore node: the largest error of the recovered
// gradient over the bore nodes, relative to eps / l, falls as dx^2. In 3D apart: the nodes on
// the bore's edges (z = 0, L), where the fit is one-sided (11-12 particles for 6 coefficients).
struct Worst {
  double inside = 0.0, edge = 0.0;
};

template <int D>
Worst smoothFieldWorst(double dx) {
  const auto setup = lameBody<D>(dx, "linear-elastic");
  const auto& X = setup.scene.particles.referencePosition;
  const Material& material = setup.scene.materials[0];
  const double eps = 3e-6, l = 0.03;
  auto field = [&](const Vec<D>& Y, Mat<D>& G) {
    Vec<D> v = Vec<D>::Zero();
    G.setZero();
    v[0] = eps * std::sin(Y[1] / l + 0.3);
    v[1] = eps * std::cos(Y[0] / l);
    G(0, 1) = eps / l * std::cos(Y[1] / l + 0.3);
    G(1, 0) = -eps / l * std::sin(Y[0] / l);
    if constexpr (D == 3) {
      v[2] = eps * std::sin((Y[0] + Y[2]) / l);
      G(2, 0) = G(2, 2) = eps / l * std::cos((Y[0] + Y[2]) / l);
    }
    return v;
  };
  std::vector<Vec<D>> u(X.size());
  Mat<D> G;
  for (std::size_t i = 0; i < X.size(); ++i)
    u[i] = field(X[i], G);
  Worst worst;
  for (const auto& s : boreStencils<D>(setup)) {
    field(X[s.particle], G);
    const Vec<D> t0 = firstPiolaKirchhoff<D>(material, Mat<D>(Mat<D>::Identity() + G)) * s.normal;
    const Mat<D> H = recoveredDisplacementGradient<D>(s, u, material, t0, 0.0, Mat<D>::Zero());
    const double e = (H - G).norm() / (eps / l);
    const bool edge = D == 3 && (X[s.particle][D - 1] < 1e-9 || X[s.particle][D - 1] > 0.05 - 1e-9);
    (edge ? worst.edge : worst.inside) = std::max(edge ? worst.edge : worst.inside, e);
  }
  std::cout << D << "D, dx " << dx << ": worst recovered gradient error " << worst.inside
            << " of eps / l (edges " << worst.edge << ")\n";
  return worst;
}

TEST(SurfaceStress, SmoothFieldAlongTheSurfaceIsSecondOrder) {
  const double r8 = smoothFieldWorst<2>(0.05 / 8).inside,
               r16 = smoothFieldWorst<2>(0.05 / 16).inside,
               r32 = smoothFieldWorst<2>(0.05 / 32).inside;
  EXPECT_LT(r16, 0.3 * r8);
  EXPECT_LT(r32, 0.3 * r16);
  // At 16 through (too slow for the suite) the worst node, on an edge, is at 0.014 (from 0.047
  // at 8: order 1.7).
  const Worst c4 = smoothFieldWorst<3>(0.05 / 4), c8 = smoothFieldWorst<3>(0.05 / 8);
  EXPECT_LT(c8.inside, 0.3 * c4.inside);
  EXPECT_LT(c8.edge, 0.06);
}

}  // namespace
}  // namespace tlsph::testing
