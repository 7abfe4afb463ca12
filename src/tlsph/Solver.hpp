// Advances a Scene in time with velocity Verlet (kick-drift-kick), keeping the energy books.
#pragma once

#include <stdexcept>
#include <vector>

#include "tlsph/Diagnostics.hpp"
#include "tlsph/Errors.hpp"
#include "tlsph/ReferenceConfiguration.hpp"
#include "tlsph/Scene.hpp"
#include "tlsph/TimeStep.hpp"
#include "tlsph/TlsphForces.hpp"

namespace tlsph {

struct SolverSettings {
  double cfl = kDefaultCfl;
  double timeStep = 0.0;  // > 0 overrides the wave-speed rule
};

// Energy books of a run. Without damping `total()` is conserved up to the time
// discretisation error: kinetic + strain + hourglass - work put in by loads and boundaries.
struct EnergyBalance {
  double kinetic = 0.0;
  double strain = 0.0;        // sum_I V_I psi(F_I), all particles (ghost F depends on the body)
  double hourglass = 0.0;     // work done against the hourglass force
  double externalWork = 0.0;  // work of body forces on free particles
  double boundaryWork = 0.0;  // work of prescribed particles on the rest
  double total() const { return kinetic + strain + hourglass - externalWork - boundaryWork; }
};

template <int D>
class Solver {
 public:
  // The scene's particle arrays must not be resized while the solver lives.
  explicit Solver(Scene<D>& scene, const SolverSettings& settings = {})
      : scene_(scene),
        ref_(buildReferenceConfiguration<D>(scene.particles.referencePosition,
                                            scene.particles.volume, checkedKernel(scene),
                                            scene.periodicBox)),
        forces_(ref_, scene.materials, scene.particles.material, scene.particles.volume,
                scene.hourglassCoefficient) {
    if (!(settings.cfl > 0.0)) throw SetupError("the CFL number must be positive");
    dt_ = settings.timeStep > 0.0 ? settings.timeStep
                                  : stableTimeStep(scene.particles, scene.materials, settings.cfl);
    for (Index i = 0; i < scene.particles.size(); ++i)
      (scene.particles.motion[i] == Motion::Free ? free_ : prescribed_).push_back(i);
    forces_.compute(scene.particles.displacement, scene.particles.force);
  }

  double time() const { return time_; }
  double timeStep() const { return dt_; }
  long stepCount() const { return steps_; }
  const ReferenceConfiguration<D>& reference() const { return ref_; }
  const TlsphForces<D>& forces() const { return forces_; }

  void step() {
    auto& p = scene_.particles;
    const Vec<D> g = scene_.gravity;
    const double halfDt = 0.5 * dt_;
    const Index nFree = static_cast<Index>(free_.size());
    // Kick, then drift; the work terms use the trapezoidal rule over the drift
    // (half with the old forces here, half with the new ones below).
    double hourglassWork = 0.0, externalWork = 0.0, boundaryWork = 0.0;
#pragma omp parallel for reduction(+ : hourglassWork, externalWork) schedule(static)
    for (Index k = 0; k < nFree; ++k) {
      const Index i = free_[k];
      p.velocity[i] += halfDt * (p.force[i] / p.mass[i] + g);
      const Vec<D> du = dt_ * p.velocity[i];
      p.displacement[i] += du;
      externalWork += 0.5 * p.mass[i] * g.dot(du);
      if (forces_.hourglassEnabled()) hourglassWork += 0.5 * forces_.hourglassForce()[i].dot(du);
    }
    for (Index i : prescribed_) {
      const Vec<D> du = dt_ * p.velocity[i];
      p.displacement[i] += du;
      boundaryWork -= 0.5 * p.force[i].dot(du);
      if (forces_.hourglassEnabled()) hourglassWork += 0.5 * forces_.hourglassForce()[i].dot(du);
    }

    forces_.compute(p.displacement, p.force);

#pragma omp parallel for reduction(+ : hourglassWork, externalWork) schedule(static)
    for (Index k = 0; k < nFree; ++k) {
      const Index i = free_[k];
      const Vec<D> du = dt_ * p.velocity[i];  // still the mid-step velocity
      externalWork += 0.5 * p.mass[i] * g.dot(du);
      if (forces_.hourglassEnabled()) hourglassWork += 0.5 * forces_.hourglassForce()[i].dot(du);
      p.velocity[i] += halfDt * (p.force[i] / p.mass[i] + g);
    }
    for (Index i : prescribed_) {
      const Vec<D> du = dt_ * p.velocity[i];
      boundaryWork -= 0.5 * p.force[i].dot(du);
      if (forces_.hourglassEnabled()) hourglassWork += 0.5 * forces_.hourglassForce()[i].dot(du);
    }

    hourglassWorkDone_ += hourglassWork;
    externalWork_ += externalWork;
    boundaryWork_ += boundaryWork;
    time_ += dt_;
    ++steps_;
  }

  EnergyBalance energyBalance() const {
    EnergyBalance e;
    e.kinetic = kineticEnergy(scene_.particles);
    e.strain = forces_.strainEnergy();
    e.hourglass = -hourglassWorkDone_;
    e.externalWork = externalWork_;
    e.boundaryWork = boundaryWork_;
    return e;
  }

 private:
  static Kernel<D> checkedKernel(const Scene<D>& scene) {
    if (scene.materials.empty()) throw SetupError("the scene has no material");
    if (scene.particles.size() == 0) throw SetupError("the scene has no particles");
    return Kernel<D>(scene.kernel, scene.supportRadius);
  }

  Scene<D>& scene_;
  ReferenceConfiguration<D> ref_;
  TlsphForces<D> forces_;
  std::vector<Index> free_, prescribed_;
  double dt_ = 0.0;
  double time_ = 0.0;
  long steps_ = 0;
  double hourglassWorkDone_ = 0.0;  // work done BY the hourglass force
  double externalWork_ = 0.0;
  double boundaryWork_ = 0.0;
};

}  // namespace tlsph
