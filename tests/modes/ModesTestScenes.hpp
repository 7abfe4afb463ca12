// Small scenes for the modal-analysis tests (tests/modes): free bodies of several shapes in 2D
// and 3D, clamped and held ones, from scene text, and the tangent of a scene at its reference
// state with the unknowns' masses, as computeModes builds them.
#pragma once

#include <memory>
#include <sstream>
#include <string>

#include "explicit/Solver.hpp"
#include "implicit/DofMap.hpp"
#include "implicit/TangentStiffness.hpp"
#include "scene/Config.hpp"
#include "scene/SceneBuilder.hpp"

namespace tlsph::testing {

enum class Shape { Box, Cylinder, Polygon };

struct Numerics {
  const char* correction = "quadratic";  // or linear
  const char* quadrature = "taylor";     // or nodal
  double alpha = 10.0;                   // hourglass penalty, 0 off
};

inline const char* shapeName(Shape s) {
  return s == Shape::Box ? "box" : s == Shape::Cylinder ? "cylinder" : "polygon";
}

// A free body (no condition) of about 60 (2D) / 60-80 (3D) particles at dx = 0.01, or with
// `hold` its face x = 0 clamped by mirrored ghosts ("clamp") or by prescribed particles
// ("prescribe").
template <int D>
std::string bodyText(Shape shape, const Numerics& n, const std::string& hold = "") {
  std::ostringstream s;
  s << "[scene]\ndimension = " << D << "\ndx = 0.01\n"
    << "[material.m]\nmodel = neo-hookean\ndensity = 1000\nyoungs_modulus = 1.0e7\n"
    << "poisson_ratio = 0.3\n"
    << "[kernel]\ncorrection = " << n.correction << "\nquadrature = " << n.quadrature << "\n"
    << "[hourglass]\nalpha = " << n.alpha << "\n[body.b]\n";
  if constexpr (D == 2) {
    if (shape == Shape::Box) s << "shape = box\nlower = 0 0\nupper = 0.1 0.06\n";
    if (shape == Shape::Cylinder) s << "shape = cylinder\ncentre = 0.045 0.045\nradius = 0.045\n";
    if (shape == Shape::Polygon)
      s << "shape = polygon\nvertices = 0 0, 0.1 0, 0.1 0.04, 0.05 0.04, 0.03 0.08, 0 0.07\n";
  } else {
    if (shape == Shape::Box) s << "shape = box\nlower = 0 0 0\nupper = 0.05 0.04 0.04\n";
    if (shape == Shape::Cylinder)
      s << "shape = cylinder\nstart = 0 0.02 0.02\nend = 0.05 0.02 0.02\nradius = 0.02\n";
    if (shape == Shape::Polygon)
      s << "shape = polygon\nvertices = 0 0, 0.06 0, 0.06 0.04, 0.02 0.05\naxis = z\nfrom = 0\n"
        << "to = 0.03\n";
  }
  if (hold == "clamp") s << "[clamp.root]\nface = x-\n";
  if (hold == "prescribe")
    s << "[prescribe.root]\nregion = root\nmotion = fixed\n[region.root]\nshape = half-space\n"
      << "point = 0.015" << (D == 3 ? " 0 0" : " 0") << "\nnormal = -1" << (D == 3 ? " 0 0" : " 0")
      << "\n";
  s << "[time]\nend = 1\n";
  return s.str();
}

template <int D>
SceneSetup<D> setupOf(const std::string& text) {
  return buildScene<D>(Config::parse(text, "modes_test.ini"));
}

// K (its update() and updateQuadrature() done) and M at the scene's reference state.
template <int D>
struct TangentAt {
  Solver<D> solver;
  DofMap<D> dofs;
  TangentStiffness<D> K;
  Eigen::VectorXd mass;
  explicit TangentAt(Scene<D>& scene)
      : solver(scene),
        dofs(scene.particles, scene.mirrorGhosts),
        K(solver.reference(), scene.materials, scene.particles.material, scene.particles.volume,
          scene.hourglass(), dofs, scene.quadrature) {
    K.update(solver.forces().deformationGradient());
    K.updateQuadrature(solver.forces().quadrature(), solver.forces().deformationGradient());
    mass.resize(K.size());
    for (Index d = 0; d < dofs.size(); ++d)
      mass.template segment<D>(D * d).setConstant(scene.particles.mass[dofs.freeParticles()[d]]);
  }
};

}  // namespace tlsph::testing
