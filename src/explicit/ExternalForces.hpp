// The scene's body forces and loads (Neumann conditions) on each particle at a time t, each
// scaled by its ramp. A following pressure (FollowingPressure.hpp) is evaluated on the
// particles' present displacements, so update() comes after every move.
#pragma once

#include <vector>

#include "model/Scene.hpp"

namespace tlsph {

template <int D>
class ExternalForces {
 public:
  ExternalForces() = default;

  // The forces at time 0; none are kept when the scene has neither gravity nor loads.
  explicit ExternalForces(const Scene<D>& scene) : scene_(&scene) {
    if (scene.gravity.isZero() && scene.loads.empty()) return;
    force_.assign(scene.particles.size(), Vec<D>::Zero());
    update(0.0);
  }

  bool any() const { return !force_.empty(); }
  // Per particle; empty when the scene has none.
  const std::vector<Vec<D>>& force() const { return force_; }

  void update(double t) {
    const auto& p = scene_->particles;
    const Vec<D> g = scene_->gravity * scene_->gravityRamp.factor(t);
    for (Index i = 0; i < p.size(); ++i)
      force_[i] = p.mass[i] * g;
    for (const auto& load : scene_->loads) {
      const double f = load.ramp.factor(t);
      if (load.following) {
        load.following->addForce(p.referencePosition, p.displacement, f, force_);
        continue;
      }
      for (std::size_t k = 0; k < load.particles.size(); ++k)
        force_[load.particles[k]] += f * load.force[k];
    }
  }

 private:
  const Scene<D>* scene_ = nullptr;
  std::vector<Vec<D>> force_;
};

}  // namespace tlsph
