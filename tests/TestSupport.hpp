// Small particle clouds and a force evaluator shared by the core tests.
#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "fast/TlsphForces.hpp"
#include "geometry/Lattice.hpp"
#include "materials/Material.hpp"
#include "method/IntegrationConstraint.hpp"
#include "method/ReferenceConfiguration.hpp"
#include "model/Scene.hpp"

namespace tlsph::testing {

// The larger of a running worst error and a new one, NaN if either is: std::max(worst, NaN)
// keeps worst, so an energy that turned NaN (J <= 0) would pass a difference check unseen.
inline double worseOf(double worst, double error) {
  return std::isnan(worst) || std::isnan(error) ? std::nan("") : std::max(worst, error);
}

// A block of counts[a] cells of size dx with every particle moved by up to
// jitter * dx per axis; volumes stay dx^D.
template <int D>
std::vector<Vec<D>> perturbedBlock(const std::array<int, D>& counts, double dx, double jitter,
                                   std::mt19937& rng) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  auto points = cellCentredLattice<D>(Vec<D>::Zero(), counts, dx);
  for (auto& x : points)
    for (int a = 0; a < D; ++a)
      x[a] += jitter * dx * unit(rng);
  return points;
}

template <int D>
Scene<D> sceneOf(const std::vector<Vec<D>>& X, double dx, double supportRatio, Material material,
                 double alpha = 0.0, HourglassForm form = HourglassForm::Energy) {
  Scene<D> scene;
  scene.hourglassForm = form;
  scene.materials.push_back(std::move(material));
  scene.supportRadius = supportRatio * dx;
  scene.hourglassCoefficient = alpha;
  const double V = std::pow(dx, D);
  for (const auto& x : X)
    scene.particles.add(x, V, density(scene.materials[0]) * V, 0);
  return scene;
}

// Internal (+ hourglass, + viscous with v) forces and strain energy as functions of the
// displacement field, from the run's fused passes (TlsphForces) or the plain loops
// (method/PairForces: PlainEvaluator), which share the constructor and compute().
template <int D, class Forces = TlsphForces<D>>
class ForceEvaluator {
 public:
  explicit ForceEvaluator(Scene<D> scene)
      : scene_(std::move(scene)),
        ref_(buildSceneReference<D>(scene_.particles.referencePosition, scene_.particles.volume,
                                    Kernel<D>(scene_.kernel, scene_.supportRadius),
                                    scene_.periodicBox, scene_.gradientCorrection,
                                    scene_.quadrature, scene_.particles.quadratureMoments(),
                                    scene_.particles.boundaryArea, scene_.particles.boundaryMoment,
                                    scene_.integrationFilter)),
        forces_(ref_, scene_.materials, scene_.particles.material, scene_.particles.volume,
                scene_.hourglass(), scene_.quadrature, scene_.viscosity, 0.5 * scene_.supportRadius,
                {}, scene_.particles.quadratureMoments()) {}
  ForceEvaluator(const ForceEvaluator&) = delete;
  ForceEvaluator& operator=(const ForceEvaluator&) = delete;

  Index size() const { return scene_.particles.size(); }
  const Scene<D>& scene() const { return scene_; }
  const ReferenceConfiguration<D>& reference() const { return ref_; }
  Forces& forces() { return forces_; }
  const std::vector<Vec<D>>& X() const { return scene_.particles.referencePosition; }

  std::vector<Vec<D>> force(const std::vector<Vec<D>>& u, const std::vector<Vec<D>>* v = nullptr) {
    std::vector<Vec<D>> f(size());
    forces_.compute(u, f, v);
    return f;
  }
  // Strain energy (with the Taylor term) plus the energy-form hourglass energy: the total
  // whose negative gradient is the force.
  double energy(const std::vector<Vec<D>>& u) {
    force(u);
    return forces_.strainEnergy() + forces_.hourglassEnergy(u);
  }
  std::vector<Vec<D>> currentPositions(const std::vector<Vec<D>>& u) const {
    std::vector<Vec<D>> x(size());
    for (Index i = 0; i < size(); ++i)
      x[i] = scene_.particles.referencePosition[i] + u[i];
    return x;
  }

 private:
  Scene<D> scene_;
  ReferenceConfiguration<D> ref_;
  Forces forces_;
};

template <int D>
Mat<D> randomMatrix(std::mt19937& rng, double scale) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  Mat<D> A;
  for (int r = 0; r < D; ++r)
    for (int c = 0; c < D; ++c)
      A(r, c) = scale * unit(rng);
  return A;
}

template <int D>
Vec<D> randomVector(std::mt19937& rng, double scale) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  Vec<D> v;
  for (int a = 0; a < D; ++a)
    v[a] = scale * unit(rng);
  return v;
}

// A proper rotation from random axis/angle (3D) or angle (2D).
template <int D>
Mat<D> randomRotation(std::mt19937& rng) {
  std::uniform_real_distribution<double> angle(-3.0, 3.0);
  if constexpr (D == 2) {
    const double t = angle(rng);
    Mat<2> R;
    R << std::cos(t), -std::sin(t), std::sin(t), std::cos(t);
    return R;
  } else {
    const Vec3 axis = randomVector<3>(rng, 1.0).normalized();
    return Eigen::AngleAxisd(angle(rng), axis).toRotationMatrix();
  }
}

inline Material testMaterial(const std::string& name) {
  return makeMaterial(name, ElasticConstants::fromYoungPoisson(2.0e6, 0.3), 1000.0);
}

// A scene file's text: a 3D rubber beam of 0.1 x 0.1 section along x, clamped at x = 0 (its
// mirrored face clamp), 4 particles through; `extra` adds sections.
inline std::string clampedBeamText(double length, const std::string& model = "neo-hookean",
                                   const std::string& extra = "") {
  return "[scene]\ndimension = 3\ndx = 0.025\n[material.rubber]\nmodel = " + model +
         "\ndensity = 1000\nyoungs_modulus = 1.0e7\npoisson_ratio = 0.3\n[body.beam]\nshape = "
         "box\nlower = 0 -0.05 -0.05\nupper = " +
         std::to_string(length) + " 0.05 0.05\n[clamp.root]\nface = x-\n[time]\nend = 1\n" + extra;
}

// A block of counts particles at spacing dx, moved by up to jitter dx, with the quadratic
// correction and (taylor) the Taylor quadrature: the Taylor term's tests' body.
template <int D>
Scene<D> taylorBlockScene(const std::string& material, double alpha, double jitter,
                          std::mt19937& rng, double dx, bool taylor = true) {
  std::array<int, D> counts;
  counts.fill(D == 2 ? 6 : 4);
  counts[0] = D == 2 ? 8 : 5;
  auto X = perturbedBlock<D>(counts, dx, jitter, rng);
  Scene<D> scene = sceneOf<D>(X, dx, 2.4, testMaterial(material), alpha);
  scene.gradientCorrection = GradientCorrection::Quadratic;
  scene.quadrature = taylor ? Quadrature::Taylor : Quadrature::Nodal;
  return scene;
}

// Random quadrature moments: mu up to 0.3 dx per axis, N = mu mu^T + a positive definite
// central part of about a lattice cell's size.
template <int D>
void addRandomMoments(Scene<D>& scene, std::mt19937& rng, double dx) {
  auto& p = scene.particles;
  p.quadratureOffset.resize(p.size());
  p.quadratureSpread.resize(p.size());
  for (Index i = 0; i < p.size(); ++i) {
    const Vec<D> mu = randomVector<D>(rng, 0.3 * dx);
    const Mat<D> B = randomMatrix<D>(rng, 0.15 * dx);
    p.quadratureOffset[i] = mu;
    p.quadratureSpread[i] =
        mu * mu.transpose() + B * B.transpose() + (dx * dx / 48.0) * Mat<D>::Identity();
  }
}

}  // namespace tlsph::testing
