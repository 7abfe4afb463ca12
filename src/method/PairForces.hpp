// The whole pair force of a step in one plain evaluation f(u, v), composed from the terms a
// scene uses, each written once in its own file:
//   F (6.69, DeformationGradient.hpp) -> P -> internal force (6.70, InternalForce.hpp)
//   [+ the Taylor quadrature term: P^q and the hyperstress force (TaylorCorrection.hpp)]
//   [+ the energy-form hourglass penalty: spring and P^hg (HourglassEnergy.hpp)]
//   [+ the textbook hourglass force (6.80)-(6.81) (GanzenmuellerHourglass.hpp)]
//   [+ artificial viscosity (6.77) (ArtificialViscosity.hpp)].
// The contract is that of TlsphForces::compute, the fused, padded and threaded passes that a
// run uses: this is the reference they are held to (tests/fast/test_equivalence.cpp), and the
// evaluation the method's tests pin the physics on.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "materials/Material.hpp"
#include "method/ArtificialViscosity.hpp"
#include "method/DeformationGradient.hpp"
#include "method/GanzenmuellerHourglass.hpp"
#include "method/HourglassEnergy.hpp"
#include "method/HourglassStiffness.hpp"
#include "method/InternalForce.hpp"
#include "method/ReferenceConfiguration.hpp"
#include "method/TaylorCorrection.hpp"
#include "model/PairTerms.hpp"
#include "model/Types.hpp"

namespace tlsph {

template <int D>
class PairForces {
 public:
  // passive: particles with an F but no energy of their own (mirrored ghosts); moments: the
  // particles' quadrature moments for the Taylor term (empty: lattice cells).
  PairForces(const ReferenceConfiguration<D>& reference, const std::vector<Material>& materials,
             const std::vector<std::uint16_t>& materialOfParticle,
             const std::vector<double>& volume, const HourglassSettings& hourglass,
             Quadrature quadrature = Quadrature::Nodal, const ViscositySettings& viscosity = {},
             double smoothingLength = 0.0, const std::vector<Index>& passive = {},
             const QuadratureMoments<D>& moments = {})
      : ref_(reference),
        materials_(materials),
        materialOf_(materialOfParticle),
        volume_(volume),
        hourglass_(hourglass) {
    if (!passive.empty()) {
      passive_.assign(ref_.particleCount(), 0);
      for (Index i : passive)
        passive_.at(i) = 1;
    }
    if (quadrature == Quadrature::Taylor)
      taylor_ = std::make_unique<TaylorCorrection<D>>(ref_, materials_, materialOf_, volume_,
                                                      passive_, moments);
    if (hourglass.enabled()) {
      pairCoefficient_ = hourglassPairCoefficients(ref_, materials_, materialOf_, volume_,
                                                   hourglass.alpha, passive_);
      // the textbook form always compares with the linear F, the energy form with the chosen
      linearPenalty_ = hourglass.form == HourglassForm::Ganzenmueller ||
                       hourglass.gradient == HourglassGradient::Linear;
      if (hourglass.form == HourglassForm::Ganzenmueller)
        textbook_ = std::make_unique<GanzenmuellerHourglass<D>>(pairCoefficient_);
    }
    if (viscosity.enabled())
      viscosity_ = std::make_unique<ArtificialViscosity<D>>(ref_, materials_, materialOf_,
                                                            smoothingLength, viscosity);
  }

  // f = the internal plus hourglass (plus viscous) force on every particle, passive ones
  // included; v only with artificial viscosity.
  void compute(const std::vector<Vec<D>>& u, std::vector<Vec<D>>& f,
               const std::vector<Vec<D>>* v = nullptr) {
    const Index n = ref_.particleCount();
    const auto& nb = ref_.neighbours;
    F_ = deformationGradients<D>(ref_, u);
    std::vector<Mat<D>> P = firstPiolaKirchhoffStresses<D>(materials_, materialOf_, F_, passive_);
    if (taylor_) {
      G_.resize(n);
      for (Index i = 0; i < n; ++i) {
        G_[i] = taylor_->secondGradients(i, u);
        P[i] += taylor_->stress(i, F_[i], G_[i]);
      }
    }
    f.assign(n, Vec<D>::Zero());
    addStressDivergence<D>(nb, ref_.correctedGradient, volume_, P, f);
    if (taylor_) taylor_->addHyperstressForce(F_, G_, f);

    if (hourglass_.enabled())
      penaltyF_ =
          linearPenalty_ ? deformationGradients<D>(ref_, linearGradientVectors(ref_), u) : F_;
    if (hourglass_.enabled() && !textbook_)
      addHourglassForce<D>(ref_, pairCoefficient_, volume_, penaltyGradientVectors(), u, penaltyF_,
                           f);
    if (textbook_) {
      hourglassForce_.assign(n, Vec<D>::Zero());
      for (Index i = 0; i < n; ++i) {
        for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k) {
          const Index j = nb.neighbour[k];
          const Vec<D>& Xij = ref_.separation[k];
          const Vec<D> xij = Xij + (u[i] - u[j]);
          hourglassForce_[i] += textbook_->pair(k, Xij, xij, penaltyF_[i], penaltyF_[j]);
        }
        hourglassForce_[i] *= volume_[i];
        f[i] += hourglassForce_[i];
      }
    }
    if (viscosity_ && v) {
      viscousForce_.assign(n, Vec<D>::Zero());
      for (Index i = 0; i < n; ++i) {
        for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k) {
          const Index j = nb.neighbour[k];
          const Vec<D> xij = ref_.separation[k] + (u[i] - u[j]);
          viscousForce_[i] += viscosity_->pair(k, xij, (*v)[i] - (*v)[j]);
        }
        viscousForce_[i] *= volume_[i];
        f[i] += viscousForce_[i];
      }
    }
  }

  bool hourglassEnabled() const { return hourglass_.enabled(); }
  bool viscosityEnabled() const { return viscosity_ != nullptr; }

  // F of every particle at the last compute().
  const std::vector<Mat<D>>& deformationGradient() const { return F_; }
  // The F the hourglass penalty compared with at the last compute() (empty when it is off).
  const std::vector<Mat<D>>& penaltyDeformationGradient() const { return penaltyF_; }
  // grad grad u at the last compute() (Taylor quadrature only).
  const std::vector<typename TaylorCorrection<D>::Gradients>& secondGradients() const { return G_; }
  const TaylorCorrection<D>* quadrature() const { return taylor_.get(); }
  // c_IJ of the penalty (empty when it is off).
  const PairArray<double>& hourglassPairCoefficient() const { return pairCoefficient_; }

  // E = sum_I V_I psi(F_I) (+ E_q) at the last compute(): minus its gradient is the internal
  // force.
  double strainEnergy() const {
    double E = tlsph::strainEnergy<D>(materials_, materialOf_, volume_, F_, passive_);
    if (taylor_) E += taylor_->energy(F_, G_);
    return E;
  }
  // E_hg of the energy form for u and the penalty's F of the last compute() (0 otherwise).
  double hourglassEnergy(const std::vector<Vec<D>>& u) const {
    if (!hourglass_.enabled() || textbook_) return 0.0;
    return tlsph::hourglassEnergy<D>(ref_, pairCoefficient_, volume_, u, penaltyF_);
  }
  // The textbook hourglass part of the last force (empty for the energy form or when off).
  const std::vector<Vec<D>>& hourglassForce() const { return hourglassForce_; }
  // The artificial-viscosity part of the last force (empty when off or without v).
  const std::vector<Vec<D>>& viscousForce() const { return viscousForce_; }

 private:
  const PairArray<Vec<D>>& penaltyGradientVectors() const {
    return linearPenalty_ ? linearGradientVectors(ref_) : ref_.correctedGradient;
  }

  const ReferenceConfiguration<D>& ref_;
  std::vector<Material> materials_;
  std::vector<std::uint16_t> materialOf_;
  std::vector<double> volume_;
  HourglassSettings hourglass_;
  std::vector<std::uint8_t> passive_;  // 1 for a passive particle; empty when there are none
  std::unique_ptr<TaylorCorrection<D>> taylor_;
  PairArray<double> pairCoefficient_;  // c_IJ
  bool linearPenalty_ = false;         // the penalty compares with the linear F
  std::unique_ptr<GanzenmuellerHourglass<D>> textbook_;
  std::unique_ptr<ArtificialViscosity<D>> viscosity_;
  std::vector<Mat<D>> F_, penaltyF_;
  std::vector<typename TaylorCorrection<D>::Gradients> G_;
  std::vector<Vec<D>> hourglassForce_, viscousForce_;
};

}  // namespace tlsph
