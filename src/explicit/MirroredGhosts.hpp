// The ghosts of mirrored clamps (MirrorGhost, docs/method.md section 3): they extrapolate the
// body across a clamped face, carry no strain energy of their own and pass their forces back
// to the particles they follow by the chain rule, which keeps the clamped system conservative.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "model/Conditions.hpp"
#include "model/Errors.hpp"
#include "model/Scene.hpp"

namespace tlsph {

template <int D>
class MirroredGhosts {
 public:
  // The ghost particles, checked: each is a mirrored particle that follows free ones, and
  // every mirrored particle is some ghost. The force pass needs the list before the solver
  // that owns the ghosts is built.
  static std::vector<Index> checkedGhostList(const Scene<D>& scene) {
    const auto& p = scene.particles;
    std::vector<Index> ghosts;
    std::vector<std::uint8_t> listed(p.size(), 0);
    auto freeParticle = [&](Index i) {
      return i >= 0 && i < p.size() && p.motion[i] == Motion::Free;
    };
    for (const auto& m : scene.mirrorGhosts) {
      if (m.ghost < 0 || m.ghost >= p.size() || p.motion[m.ghost] != Motion::Mirrored ||
          !freeParticle(m.mirror) || (m.second >= 0 && !freeParticle(m.second)))
        throw SetupError("mirror ghost " + std::to_string(m.ghost) + " of particle " +
                         std::to_string(m.mirror) +
                         " must be a mirrored particle whose mirror particles are free ones");
      if (m.motion >= static_cast<int>(scene.prescriptions.size()))
        throw SetupError("mirror ghost " + std::to_string(m.ghost) + " names motion rule " +
                         std::to_string(m.motion) + ", which does not exist");
      listed[m.ghost] = 1;
      ghosts.push_back(m.ghost);
    }
    for (Index i = 0; i < p.size(); ++i)
      if (p.motion[i] == Motion::Mirrored && !listed[i])
        throw SetupError("particle " + std::to_string(i) + " is mirrored but has no mirror");
    return ghosts;
  }

  MirroredGhosts() = default;

  // The scene's ghosts (checked by checkedGhostList), with their drive at time 0.
  explicit MirroredGhosts(const Scene<D>& scene) : scene_(&scene) {
    for (const auto& m : scene.mirrorGhosts)
      if (m.motion >= 0 && scene.prescriptions[m.motion].motion != PrescribedMotion::Fixed)
        moving_ = true;
    for (std::size_t k = 0; k < scene.mirrorGhosts.size(); ++k)
      own_.push_back(k);
    updateDrive(0.0);
  }

  // Some mirrored face follows a moving prescription (else every drive is zero and not kept).
  bool moving() const { return moving_; }

  // The ghosts (indices into scene.mirrorGhosts) this rank moves and whose forces it chains,
  // all of them in a serial run: a ghost is on the rank of the particles it follows.
  const std::vector<std::size_t>& own() const { return own_; }
  void keepOwn(const std::vector<std::uint8_t>& mine) {
    std::erase_if(own_, [&](std::size_t k) { return !mine[scene_->mirrorGhosts[k].ghost]; });
  }

  // The prescribed part of each ghost's displacement at time t and its rate,
  //   d_g = u_p(X_g) - w1 u_p(X_1) - w2 u_p(X_2)   (MirrorGhost);
  // kept only when some mirrored face moves.
  void updateDrive(double t) {
    if (!moving_) return;
    const auto& X = scene_->particles.referencePosition;
    const auto n = scene_->mirrorGhosts.size();
    drive_.assign(n, Vec<D>::Zero());
    driveRate_.assign(n, Vec<D>::Zero());
    for (std::size_t k = 0; k < n; ++k) {
      const auto& m = scene_->mirrorGhosts[k];
      if (m.motion < 0) continue;
      const auto& rule = scene_->prescriptions[m.motion];
      auto part = [&](Vec<D> (*at)(const Prescription<D>&, const Vec<D>&, double)) {
        Vec<D> d = at(rule, X[m.ghost], t) - m.w1 * at(rule, X[m.mirror], t);
        if (m.second >= 0) d -= m.w2 * at(rule, X[m.second], t);
        return d;
      };
      drive_[k] = part(prescribedDisplacementAt<D>);
      driveRate_[k] = part(prescribedVelocityAt<D>);
    }
  }

  // Moves the drive on to time t and returns its change, for the work the moving faces do
  // over the step; empty when no face moves.
  std::vector<Vec<D>> advanceDrive(double t) {
    if (!moving_) return {};
    std::vector<Vec<D>> change = drive_;
    updateDrive(t);
    for (std::size_t k = 0; k < drive_.size(); ++k)
      change[k] = drive_[k] - change[k];
    return change;
  }

  // A static state: the faces where the drive puts them, at rest.
  void holdDriveAt(double t) {
    if (!moving_) return;
    updateDrive(t);
    for (auto& r : driveRate_)
      r.setZero();
  }

  const std::vector<Vec<D>>& drive() const { return drive_; }

  // u_ghost = d_g + w1 u_1 + w2 u_2, the same for v: the ghosts extrapolate the body across
  // the face.
  void move(ParticleSet<D>& p) const {
    for (std::size_t k = 0; k < scene_->mirrorGhosts.size(); ++k) {
      const auto& m = scene_->mirrorGhosts[k];
      p.displacement[m.ghost] = m.w1 * p.displacement[m.mirror];
      p.velocity[m.ghost] = m.w1 * p.velocity[m.mirror];
      if (m.second >= 0) {
        p.displacement[m.ghost] += m.w2 * p.displacement[m.second];
        p.velocity[m.ghost] += m.w2 * p.velocity[m.second];
      }
      if (moving_) {
        p.displacement[m.ghost] += drive_[k];
        p.velocity[m.ghost] += driveRate_[k];
      }
    }
  }

  // The chain rule of the extrapolation: -dE/du_1 gains w1 (-dE/du_ghost), -dE/du_2 gains
  // w2 (-dE/du_ghost). The ghost keeps its own force, from which its reaction is computed.
  // In this order, serially: two faces' ghosts can share a mirror particle.
  void chainForces(std::vector<Vec<D>>& force) const {
    for (std::size_t k : own_) {
      const auto& m = scene_->mirrorGhosts[k];
      force[m.mirror] += m.w1 * force[m.ghost];
      if (m.second >= 0) force[m.second] += m.w2 * force[m.ghost];
    }
  }

  // Half the work the moving faces do over a step with the ghosts' forces at one end of it
  // (the trapezoidal rule): -f_ghost . (change of the ghost's prescribed part), booked as
  // boundary work. Nothing when no face moves.
  void bookDriveWork(const std::vector<Vec<D>>& force, const std::vector<Vec<D>>& change,
                     double& boundaryWork) const {
    if (change.empty()) return;
    for (std::size_t k : own_)
      boundaryWork -= 0.5 * force[scene_->mirrorGhosts[k].ghost].dot(change[k]);
  }

  // The ghosts' part of the reaction of prescription r: the net force the chain rule leaves on
  // the body, -(1 - w1 - w2) f_ghost, of each ghost that follows r.
  void addReaction(std::size_t r, const std::vector<Vec<D>>& force, Vec<D>& R) const {
    for (const auto& m : scene_->mirrorGhosts)
      if (m.motion == static_cast<int>(r)) R -= (1.0 - m.w1 - m.w2) * force[m.ghost];
  }

 private:
  const Scene<D>* scene_ = nullptr;
  bool moving_ = false;
  std::vector<std::size_t> own_;
  std::vector<Vec<D>> drive_, driveRate_;  // per ghost: prescribed part of u and of v
};

}  // namespace tlsph
