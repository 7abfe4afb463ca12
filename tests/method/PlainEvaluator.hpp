// The plain reference evaluation (method/PairForces.hpp) of a scene, with the interface of
// TestSupport's ForceEvaluator: the method's tests pin the physics on the plain loops.
#pragma once

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "TestSupport.hpp"
#include "method/PairForces.hpp"

namespace tlsph::testing {

template <int D>
class PlainEvaluator {
 public:
  explicit PlainEvaluator(Scene<D> scene)
      : scene_(std::move(scene)),
        ref_(buildReferenceConfiguration<D>(scene_.particles.referencePosition,
                                            scene_.particles.volume,
                                            Kernel<D>(scene_.kernel, scene_.supportRadius),
                                            scene_.periodicBox, scene_.gradientCorrection)),
        forces_(ref_, scene_.materials, scene_.particles.material, scene_.particles.volume,
                scene_.hourglass(), scene_.quadrature, scene_.viscosity,
                0.5 * scene_.supportRadius) {}
  PlainEvaluator(const PlainEvaluator&) = delete;
  PlainEvaluator& operator=(const PlainEvaluator&) = delete;

  Index size() const { return scene_.particles.size(); }
  const Scene<D>& scene() const { return scene_; }
  const ReferenceConfiguration<D>& reference() const { return ref_; }
  PairForces<D>& forces() { return forces_; }
  const std::vector<Vec<D>>& X() const { return scene_.particles.referencePosition; }

  std::vector<Vec<D>> force(const std::vector<Vec<D>>& u, const std::vector<Vec<D>>* v = nullptr) {
    std::vector<Vec<D>> f;
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
  PairForces<D> forces_;
};

// sum_I x_I x f_I (the z component in 2D).
template <int D>
Vec3 torque(const std::vector<Vec<D>>& x, const std::vector<Vec<D>>& f) {
  Vec3 sum = Vec3::Zero();
  for (std::size_t i = 0; i < x.size(); ++i) {
    Vec3 xi = Vec3::Zero(), fi = Vec3::Zero();
    xi.template head<D>() = x[i];
    fi.template head<D>() = f[i];
    sum += xi.cross(fi);
  }
  return sum;
}

// Largest |f - (-dE/du)| over the particles and components, dE/du by central differences of
// step h; fmax (out) the largest |f| component.
template <int D, class Evaluator>
double energyGradientError(Evaluator& eval, std::vector<Vec<D>> u, double h, double& fmax) {
  const auto f = eval.force(u);
  fmax = 0.0;
  for (const auto& fi : f)
    fmax = std::max(fmax, fi.cwiseAbs().maxCoeff());
  double worst = 0.0;
  for (Index i = 0; i < eval.size(); ++i)
    for (int a = 0; a < D; ++a) {
      const double saved = u[i][a];
      u[i][a] = saved + h;
      const double plus = eval.energy(u);
      u[i][a] = saved - h;
      const double minus = eval.energy(u);
      u[i][a] = saved;
      worst = std::max(worst, std::abs(-(plus - minus) / (2 * h) - f[i][a]));
    }
  return worst;
}

}  // namespace tlsph::testing
