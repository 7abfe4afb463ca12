// The unknowns of a static solve and of the tangent stiffness: the displacements of the free
// particles. Every other particle's displacement follows from them (docs/method.md section 3):
//   prescribed particles: u = u_p(t), no unknown;
//   mirrored ghosts:      u_g = d_g(t) + w1 u_1 + w2 u_2  (MirrorGhost).
// So a variation of the full displacement vector is T dv, with T this map's linear part, and
// the forces on the unknowns are T^T f (the chain rule that MirroredGhosts::chainForces applies).
#pragma once

#include <Eigen/Core>
#include <utility>
#include <vector>

#include "model/Conditions.hpp"
#include "model/Particles.hpp"
#include "model/Types.hpp"

namespace tlsph {

template <int D>
class DofMap {
 public:
  // One term of a particle's displacement variation: weight * du of unknown particle `dof`.
  struct Term {
    Index dof;  // index of the free particle among the unknowns
    double weight;
  };

  DofMap(const ParticleSet<D>& particles, const std::vector<MirrorGhost>& ghosts)
      : dofOf_(particles.size(), -1), first_(particles.size() + 1, 0) {
    for (Index i = 0; i < particles.size(); ++i)
      if (particles.motion[i] == Motion::Free) {
        dofOf_[i] = static_cast<Index>(freeParticles_.size());
        freeParticles_.push_back(i);
      }
    std::vector<std::vector<Term>> expansion(particles.size());
    for (Index i : freeParticles_)
      expansion[i].push_back({dofOf_[i], 1.0});
    for (const auto& m : ghosts) {
      expansion[m.ghost].push_back({dofOf_[m.mirror], m.w1});
      if (m.second >= 0) expansion[m.ghost].push_back({dofOf_[m.second], m.w2});
    }
    for (Index i = 0; i < particles.size(); ++i) {
      first_[i + 1] = first_[i] + static_cast<Index>(expansion[i].size());
      terms_.insert(terms_.end(), expansion[i].begin(), expansion[i].end());
    }
    ghosts_ = ghosts;
  }

  // Number of unknown particles (the system has D times as many scalar unknowns).
  Index size() const { return static_cast<Index>(freeParticles_.size()); }
  const std::vector<Index>& freeParticles() const { return freeParticles_; }
  // The mirrored ghosts: particles that follow others and carry no strain energy of their own.
  std::vector<Index> ghostParticles() const {
    std::vector<Index> g;
    for (const auto& m : ghosts_)
      g.push_back(m.ghost);
    return g;
  }
  // Index among the unknowns of particle i, or -1 when it is not free.
  Index dofOf(Index i) const { return dofOf_[i]; }

  // The terms of particle i's displacement variation (none for a prescribed particle).
  std::pair<const Term*, const Term*> terms(Index i) const {
    return {terms_.data() + first_[i], terms_.data() + first_[i + 1]};
  }

  // dv (D per unknown, stacked) -> the full variation T dv on every particle.
  void expand(const Eigen::VectorXd& dv, std::vector<Vec<D>>& full) const {
    for (Index i = 0; i < static_cast<Index>(full.size()); ++i) {
      Vec<D> value = Vec<D>::Zero();
      for (Index t = first_[i]; t < first_[i + 1]; ++t)
        value += terms_[t].weight * dv.template segment<D>(D * terms_[t].dof);
      full[i] = value;
    }
  }

  // Forces on every particle -> T^T f on the unknowns (a ghost's force goes to the particles
  // it follows, with their weights).
  void gather(const std::vector<Vec<D>>& f, Eigen::VectorXd& out) const {
    out.resize(D * size());
    for (Index d = 0; d < size(); ++d)
      out.template segment<D>(D * d) = f[freeParticles_[d]];
    for (const auto& m : ghosts_) {
      out.template segment<D>(D * dofOf_[m.mirror]) += m.w1 * f[m.ghost];
      if (m.second >= 0) out.template segment<D>(D * dofOf_[m.second]) += m.w2 * f[m.ghost];
    }
  }

 private:
  std::vector<Index> dofOf_;
  std::vector<Index> freeParticles_;
  std::vector<Index> first_;  // CSR offsets into terms_, per particle
  std::vector<Term> terms_;
  std::vector<MirrorGhost> ghosts_;
};

}  // namespace tlsph
