// Where the scene's prescribed particles are and how fast they move: at the end of an explicit
// step, and at a load time of a static solve (docs/method.md section 3). The rules themselves
// (Prescription, the one velocity switch) are model/Conditions.hpp's.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "model/Conditions.hpp"
#include "model/Errors.hpp"
#include "model/Scene.hpp"

namespace tlsph {

// Displacement of a particle at reference position X that started at displacement u0, rotated
// by `rule` to time t: x = point + R(theta(t)) (x_start - point), u = x - X. Exact at every
// time, so a rotation does not drift however many steps it takes.
template <int D>
Vec<D> rotatedDisplacement(const Prescription<D>& rule, const Vec<D>& X, const Vec<D>& u0,
                           double t) {
  const Mat<D> R = rotationMatrix<D>(rule.axis, rampedAngle(rule.rate, rule.ramp, t));
  return Vec<D>(rule.point + R * (X + u0 - rule.point) - X);
}

// The particles with Motion::Prescribed, each by its slot k (their order in the particle
// arrays), with the rule that moves it and where it started. A prescribed particle no rule
// names keeps its initial velocity.
template <int D>
class PrescribedParticles {
 public:
  PrescribedParticles() = default;

  // Every particle a prescription names must be a prescribed one.
  explicit PrescribedParticles(const Scene<D>& scene) : scene_(&scene) {
    const auto& p = scene.particles;
    std::vector<int> slot(p.size(), -1);
    for (Index i = 0; i < p.size(); ++i)
      if (p.motion[i] == Motion::Prescribed) {
        slot[i] = static_cast<int>(particles_.size());
        particles_.push_back(i);
      }
    rule_.assign(particles_.size(), -1);
    for (std::size_t r = 0; r < scene.prescriptions.size(); ++r)
      for (Index i : scene.prescriptions[r].particles) {
        if (i < 0 || i >= p.size() || slot[i] < 0)
          throw SetupError("prescription '" + scene.prescriptions[r].name + "' names particle " +
                           std::to_string(i) + ", which is not a prescribed particle");
        rule_[slot[i]] = static_cast<int>(r);
      }
    start_.reserve(particles_.size());
    for (Index i : particles_)
      start_.push_back(p.displacement[i]);
    for (std::size_t k = 0; k < particles_.size(); ++k)
      own_.push_back(k);
  }

  std::size_t size() const { return particles_.size(); }
  Index particle(std::size_t k) const { return particles_[k]; }
  const std::vector<Index>& particles() const { return particles_; }

  // The slots this rank moves (all of them in a serial run), ascending.
  const std::vector<std::size_t>& own() const { return own_; }
  void keepOwn(const std::vector<std::uint8_t>& mine) {
    std::erase_if(own_, [&](std::size_t k) { return !mine[particles_[k]]; });
  }

  // Displacement of slot k at the end of a step of size dt that ends at time t. A velocity
  // rule is integrated with the midpoint rule, as the kicks integrate a free particle;
  // the other rules are exact.
  Vec<D> displacementAtStepEnd(std::size_t k, double t, double dt) const {
    const Index i = particles_[k];
    const auto& p = scene_->particles;
    if (rule_[k] < 0) return p.displacement[i] + dt * p.velocity[i];  // keeps its velocity
    const auto& rule = scene_->prescriptions[rule_[k]];
    switch (rule.motion) {
      case PrescribedMotion::Fixed:
        return start_[k];
      case PrescribedMotion::Velocity:
        return p.displacement[i] + dt * rule.value * rule.ramp.factor(t - 0.5 * dt);
      case PrescribedMotion::Displacement:
        return start_[k] + rule.value * rule.ramp.factor(t);
      case PrescribedMotion::Rotation:
        return rotatedDisplacement(rule, p.referencePosition[i], start_[k], t);
    }
    return p.displacement[i];
  }

  // Displacement of slot k at load time t of a static solve: exact for every rule (a velocity
  // rule's displacement is its integral from 0); an unnamed particle stays where it started.
  Vec<D> staticDisplacement(std::size_t k, double t) const {
    const Index i = particles_[k];
    const auto& p = scene_->particles;
    if (rule_[k] < 0) return start_[k];
    const auto& rule = scene_->prescriptions[rule_[k]];
    if (rule.motion == PrescribedMotion::Rotation)
      return rotatedDisplacement(rule, p.referencePosition[i], start_[k], t);
    return Vec<D>(start_[k] + prescribedDisplacementAt(rule, p.referencePosition[i], t));
  }

  // Velocity of slot k at time t, at the particle's present position.
  Vec<D> velocity(std::size_t k, double t) const {
    const Index i = particles_[k];
    const auto& p = scene_->particles;
    if (rule_[k] < 0) return p.velocity[i];
    const Vec<D> x = p.referencePosition[i] + p.displacement[i];
    return prescribedVelocityAtPosition(scene_->prescriptions[rule_[k]], x, t);
  }

 private:
  const Scene<D>* scene_ = nullptr;
  std::vector<Index> particles_;
  std::vector<std::size_t> own_;
  std::vector<int> rule_;      // index into scene.prescriptions, or -1
  std::vector<Vec<D>> start_;  // displacement at the start of the run
};

}  // namespace tlsph
