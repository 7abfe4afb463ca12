// The force of method/InternalForce.hpp (6.70) on F of method/DeformationGradient.hpp (6.69),
// with the terms a scene adds, in fused, padded pair passes (docs/method.md section 2):
//   u -> F (6.69) -> P [+ P^q (TaylorQuadrature)] [-> P + P^hg and springs (EnergyHourglass)]
//   -> internal force (6.70) [+ textbook hourglass pair force (6.80, 6.81)]
//   [+ artificial viscosity (6.77)].
// The corrected gradient vectors g_IJ (ReferenceConfiguration) carry L^{-1}: with them
// F_I = 1 + sum_J (u_J - u_I) (x) g_IJ and f_I = -dE/du_I = V_I (P_I G_I - sum_J P_J t_IJ),
// which for the linear correction is (6.70): V_I sum_J V_J (B_I + B_J) gradW_IJ, B = P L^{-T}.
// Each auxiliary term is its own operator (EnergyHourglass, TaylorQuadrature,
// GanzenmuellerHourglass, ArtificialViscosity); the force pass is instantiated for the terms the
// scene uses, so a term that is off is not computed and the loops carry no branch on options.
//
// This file holds the choices (constructor) and the order of the passes (compute). The passes
// are members defined in files of their own, included at the end (members: they read and write
// this class's arrays):
//   StressPass.hpp     u -> F -> P (+ P^q), and what observers read of F
//   PaddedGradU.hpp    3D: grad u of two particles at a time, padded
//   HourglassPass.hpp  P + P^hg and the springs of the energy penalty
//   ForcePass.hpp      the stresses -> f, gathered or summed from the sources
//   Traffic.hpp        the bytes one compute() moves
#pragma once

#include <algorithm>
#include <cstdint>
#include <memory>
#include <span>
#include <type_traits>
#include <variant>
#include <vector>

#include "distributed/Communicator.hpp"
#include "execution/MeetInTheMiddle.hpp"
#include "execution/OrderedSum.hpp"
#include "execution/Prefetch.hpp"
#include "fast/EnergyHourglass.hpp"
#include "fast/InternalForceScatter.hpp"
#include "fast/Padded.hpp"
#include "fast/SharedRows.hpp"
#include "fast/TaylorQuadrature.hpp"
#include "materials/Material.hpp"
#include "method/ArtificialViscosity.hpp"
#include "method/GanzenmuellerHourglass.hpp"
#include "method/HourglassStiffness.hpp"
#include "method/ReferenceConfiguration.hpp"
#include "model/PairTerms.hpp"
#include "model/Types.hpp"

namespace tlsph {

template <int D>
class TlsphForces {
 public:
  TlsphForces(const ReferenceConfiguration<D>& reference, const std::vector<Material>& materials,
              const std::vector<std::uint16_t>& materialOfParticle,
              const std::vector<double>& volume, const HourglassSettings& hourglass,
              Quadrature quadrature = Quadrature::Nodal, const ViscositySettings& viscosity = {},
              double smoothingLength = 0.0, const std::vector<Index>& passive = {},
              const QuadratureMoments<D>& moments = {})
      : ref_(reference),
        materials_(materials),
        volume_(volume),
        hourglass_(hourglass),
        F_(reference.particleCount(), Mat<D>::Identity()) {
    const Index n = reference.particleCount();
    // The pair loops stream only the distinct rows of the gradient vectors (SharedRows.hpp).
    reverseGradient_ = SharedRows<Vec<D>>(reference.neighbours, reference.reverseGradient);
    // (the Taylor fit holds g_IJ for the particles with a stress; passive ones read it here)
    if (quadrature != Quadrature::Taylor || !passive.empty())
      correctedGradient_ = SharedRows<Vec<D>>(reference.neighbours, reference.correctedGradient);
    particlesOfMaterial_.resize(materials.size());
    // Passive particles (mirrored ghosts) get an F but no stress and no strain energy.
    std::vector<std::uint8_t> isPassive;
    if (!passive.empty()) {
      isPassive.assign(n, 0);
      for (Index i : passive)
        isPassive.at(i) = 1;
    }
    for (Index i = 0; i < n; ++i)
      if (isPassive.empty() || !isPassive[i])
        particlesOfMaterial_.at(materialOfParticle[i]).push_back(i);
    passive_ = passive;
    if (quadrature == Quadrature::Taylor) {
      quadrature_ = std::make_unique<TaylorQuadrature<D>>(reference, materials, materialOfParticle,
                                                          volume, isPassive, moments);
    } else {
      P_.assign(n, Mat<D>::Zero());  // (with Taylor, P is only a part of P + P^q)
    }
    if (hourglass.enabled()) {
      auto c = hourglassPairCoefficients(reference, materials, materialOfParticle, volume,
                                         hourglass.alpha, isPassive);
      hourglassStiffness_ = hourglassParticleStiffness(reference, c, volume);
      // The textbook form always compares with the linear F; the energy form with the one
      // chosen. With the linear correction there is only one F.
      const bool linearF = hourglass.form == HourglassForm::Ganzenmueller ||
                           hourglass.gradient == HourglassGradient::Linear;
      separateHourglassGradient_ = linearF && !reference.linearGradient.empty();
      if (separateHourglassGradient_) {
        hourglassF_.assign(n, Mat<D>::Identity());
        linearGradient_ = SharedRows<Vec<D>>(reference.neighbours, reference.linearGradient);
      }
      if (hourglass.form == HourglassForm::Energy) {
        energyHourglass_ = std::make_unique<EnergyHourglass<D>>(reference, std::move(c), volume);
        stress_.assign(n, PaddedMat<D>::Zero());
        if constexpr (D == 3)  // the penalty's gathered F, padded
          paddedPenaltyF_.assign(n, padded<D, D>(Mat<D>::Identity()));
        if (separateHourglassGradient_) linearReverseGradients(volume);
      } else {
        ganzenmueller_ = std::make_unique<GanzenmuellerHourglass<D>>(std::move(c));
        hourglassForce_.assign(n, Vec<D>::Zero());
      }
    }
    if (viscosity.enabled()) {
      viscosity_ = std::make_unique<ArtificialViscosity<D>>(
          reference, materials, materialOfParticle, smoothingLength, viscosity);
      viscousForce_.assign(n, Vec<D>::Zero());
    }
    // P + P^q: written straight into P + P^hg's array when the penalty adds P^hg in place
    if (quadrature_ && !penaltyReadsF()) quadratureStress_.assign(n, PaddedMat<D>::Zero());
    // 3D: u padded for the pair loops that gather it (the quadrature's F pass, the penalty)
    if (D == 3 && (quadrature_ || energyHourglass_)) paddedU_.assign(n, PaddedVec<D>::Zero());
    // The force pass summed from its sources when it has no other pair term
    if (!ganzenmueller_ && !viscosity_ && !separateHourglassGradient_) {
      if (quadrature_)
        taylorScatter_ = std::make_unique<InternalForceScatter<D, true>>(
            reference.neighbours, reverseGradient_, &quadrature_->reverseRows(),
            forcePassStressIsPadded());
      else
        nodalScatter_ = std::make_unique<InternalForceScatter<D, false>>(
            reference.neighbours, reverseGradient_, nullptr, forcePassStressIsPadded());
    }
    prefetchGathers_ = gathersFromMemory(gatheredBytesPerParticle() * n);
  }

  // A distributed run: this rank computes the particles it owns (ascending), and
  // compute() brings from their owners, through comm, what its pair loops read of the halo.
  void distribute(const std::vector<Index>& owned, Communicator* comm) {
    comm_ = comm;
    owned_ = owned;
    std::vector<std::uint8_t> mine(ref_.particleCount(), 0);
    for (Index i : owned)
      mine[i] = 1;
    ownedOfMaterial_ = particlesOfMaterial_;
    for (auto& group : ownedOfMaterial_)
      std::erase_if(group, [&](Index i) { return !mine[i]; });
    ownedPassive_ = passive_;
    std::erase_if(ownedPassive_, [&](Index i) { return !mine[i]; });
    // a rank gathers about its own particles' values (and its halo's)
    prefetchGathers_ = gathersFromMemory(gatheredBytesPerParticle() * double(owned.size()));
  }

  // Every rank's entries of what observers read (F, the hourglass and viscous forces, the
  // quadrature's second gradients) onto every rank; nothing in a serial run.
  void gatherAll() {
    if (!comm_) return;
    observe();
    comm_->gatherAll(F_);
    comm_->gatherAll(hourglassF_);
    comm_->gatherAll(hourglassForce_);
    comm_->gatherAll(viscousForce_);
    if (quadrature_) quadrature_->gatherAll(*comm_);
  }

  bool hourglassEnabled() const { return hourglass_.enabled(); }
  double hourglassCoefficient() const { return hourglass_.alpha; }
  const HourglassSettings& hourglass() const { return hourglass_; }
  // True when the hourglass force is a state function's gradient (its energy is booked
  // directly); false for the textbook form, whose work the solver integrates.
  bool hourglassConservative() const { return energyHourglass_ != nullptr; }
  bool viscosityEnabled() const { return viscosity_ != nullptr; }

  // Overwrites f with the internal plus hourglass (plus viscous) force on every particle,
  // ghosts included (on a prescribed particle it is the reaction). v is needed only with
  // artificial viscosity. Distributed: on the owned particles, and u (and v) must hold the
  // halo's values.
  void compute(const std::vector<Vec<D>>& u, std::vector<Vec<D>>& f,
               const std::vector<Vec<D>>* v = nullptr) {
    observed_ = false;
    // u -> F -> P (+ P^q): StressPass.hpp
    padDisplacements(u);
    quadrature_ ? stressPass<true>(u) : stressPass<false>(u);
    // -> P + P^hg and the springs: HourglassPass.hpp. The penalty reads the neighbours' F (the one
    // it compares with; padded for the energy form).
    if (comm_ && hourglass_.enabled()) {
      if (energyHourglass_)
        comm_->exchangeHalo(penaltyGradient());
      else
        comm_->exchangeHalo(separateHourglassGradient_ ? hourglassF_ : F_);
    }
    // P^hg of the linear F goes through the linear gradient vectors: its own sum.
    if (energyHourglass_) {
      // what the force pass sends through g_IJ: P (+ P^q) + P^hg of the same F
      if (separateHourglassGradient_)
        hourglassStress(u, static_cast<const Mat<D>*>(nullptr));
      else if (quadrature_)
        hourglassStress(u, stress_.data());  // P + P^q written there: P^hg added in place
      else
        hourglassStress(u, P_.data());
    }
    if (comm_) {  // the force pass reads the neighbours' stresses (and hyperstresses)
      if (energyHourglass_) comm_->exchangeHalo(stress_);
      if (!energyHourglass_ || separateHourglassGradient_) {
        if (quadrature_)
          comm_->exchangeHalo(quadratureStress_);
        else
          comm_->exchangeHalo(P_);
      }
      if (quadrature_) quadrature_->exchangeHalo(*comm_);
    }
    // -> f: ForcePass.hpp
    const bool viscous = viscosity_ && v != nullptr;
    if (quadrature_)
      forcePass<true>(u, f, v, viscous);
    else
      forcePass<false>(u, f, v, viscous);
  }

  // F of every particle at the last compute().
  const LargeArray<Mat<D>>& deformationGradient() const {
    observe();
    return F_;
  }
  // The textbook hourglass part of the last computed force (empty for the energy form and
  // when the term is off); the solver integrates its work.
  const std::vector<Vec<D>>& hourglassForce() const { return hourglassForce_; }
  // The artificial-viscosity part of the last computed force (empty when off).
  const std::vector<Vec<D>>& viscousForce() const { return viscousForce_; }

  // E = sum_I V_I psi(F_I) at the last computed F: the discrete strain energy whose negative
  // gradient is the internal force.
  double strainEnergy() const {
    observe();
    double total = 0.0;
    for (std::size_t m = 0; m < materials_.size(); ++m) {
      const auto& group = particlesOfMaterial_[m];
      total += std::visit(
          [&](const auto& model) {
            return orderedSum(static_cast<Index>(group.size()), [&](Index p) {
              return volume_[group[p]] * strainEnergyDensity<D>(model, F_[group[p]]);
            });
          },
          materials_[m]);
    }
    if (quadrature_) total += quadrature_->energy(F_);  // E_q: part of the strain energy
    return total;
  }

  // The quadrature correction (null unless [kernel] quadrature = taylor), its second
  // gradients those of the last compute().
  const TaylorQuadrature<D>* quadrature() const {
    observe();
    return quadrature_.get();
  }

  // E_hg of the energy form for the displacements u of the last compute() (0 otherwise);
  // distributed: a collective, after gatherAll().
  double hourglassEnergy(const std::vector<Vec<D>>& u) const {
    observe();
    return energyHourglass_
               ? energyHourglass_->energy(u, separateHourglassGradient_ ? hourglassF_ : F_,
                                          comm_ ? &owned_ : nullptr, comm_)
               : 0.0;
  }

  // The memory traffic of one compute(), counted from the arrays the passes touch (Traffic.hpp).
  struct Traffic;
  inline Traffic traffic() const;

  // Whether the force pass and the penalty prefetch the neighbours' values they gather
  // (Prefetch.hpp: on when those arrays are larger than twice the last-level cache). Results
  // are the same either way; the setter is for the tests.
  bool prefetchGathers() const { return prefetchGathers_; }
  void prefetchGathers(bool on) { prefetchGathers_ = on; }

  // Whether the force pass is summed from its sources (InternalForceScatter: when it has no
  // pair term but the internal force) rather than gathered. The same bits either way; the
  // setter (off) is for the tests.
  bool scattersInternalForce() const { return scatter_ && (taylorScatter_ || nodalScatter_); }
  void scatterInternalForce(bool on) { scatter_ = on; }

  // K_I = sum_J k_IJ per particle: the penalty's spring stiffness (empty when it is off).
  const std::vector<double>& hourglassStiffness() const { return hourglassStiffness_; }

 private:
  // The constructor's choices.
  // 3D: the F pass writes the padded F the energy penalty gathers (unless the penalty has its
  // own linear F, written by that F's pass).
  bool penaltyReadsF() const { return energyHourglass_ && !separateHourglassGradient_; }
  // Whether the F pass writes F_ itself; in 3D with the penalty on F, F lives in the padded
  // copy the penalty gathers and observe() copies it out.
  bool storesF() const { return !(D == 3 && penaltyReadsF()); }
  // The stress the force pass sends through the gradient vectors: P (+ P^q), or that plus
  // P^hg (or P^hg alone through the linear vectors), padded but for P alone.
  bool forcePassStressIsPadded() const {
    return (energyHourglass_ && !separateHourglassGradient_) || quadrature_;
  }

  // The passes, defined in their files. Declared inline: a file that sees only the extern
  // instantiation below may then still inline them, as it inlines the members defined here.
  // StressPass.hpp: u -> F -> P (+ P^q)
  inline void padDisplacements(const std::vector<Vec<D>>& u);
  template <bool Taylor>
  inline void stressPass(const std::vector<Vec<D>>& u);
  template <class Model, bool Taylor, bool PaddedF>
  inline void deformationAndStress(const Model* model, const std::vector<Index>& group,
                                   const std::vector<Vec<D>>& u);
  inline Mat<D> deformationGradientOf(Index i, const std::vector<Vec<D>>& u,
                                      const SharedRows<Vec<D>>& gradients) const;
  inline void observe() const;
  // PaddedGradU.hpp: 3D, grad u of two particles at a time
  [[gnu::always_inline]] inline void paddedGradU(Index i0, Index i1, PaddedMat<D>& gradU0,
                                                 PaddedMat<D>& gradU1) const;
  [[gnu::always_inline]] inline void paddedGradU(Index i, PaddedMat<D>& gradU) const;
  [[gnu::always_inline]] inline void addPaddedPair(PaddedMat<D>& sum, const PaddedVec<D>& ui,
                                                   Index k, const Vec<D>* g, bool ahead) const;
  // HourglassPass.hpp: P + P^hg and the springs
  inline LargeArray<PaddedMat<D>>& penaltyGradient();
  template <class PM>
  inline void hourglassStress(const std::vector<Vec<D>>& u, const PM* P);
  inline void linearReverseGradients(const std::vector<double>& volume);
  // ForcePass.hpp: the stresses -> f
  template <bool Taylor>
  inline void forcePass(const std::vector<Vec<D>>& u, std::vector<Vec<D>>& f,
                        const std::vector<Vec<D>>* v, bool viscous);
  template <bool Taylor, bool Gather>
  inline void forcePass(const std::vector<Vec<D>>& u, std::vector<Vec<D>>& f,
                        const std::vector<Vec<D>>* v, bool viscous);
  template <bool Taylor, bool Gather, class SM>
  inline void forcePass(const LargeArray<SM>& S, const std::vector<Vec<D>>& u,
                        std::vector<Vec<D>>& f, const std::vector<Vec<D>>* v, bool viscous);
  template <bool Ganzenmueller, bool Viscous, bool SeparateHourglassStress, bool Taylor,
            bool Gather, class SM>
  inline void accumulateForces(const LargeArray<SM>& S, const std::vector<Vec<D>>& u,
                               std::vector<Vec<D>>& f, const std::vector<Vec<D>>* velocity);
  template <bool Taylor, class SM>
  inline void scatterForces(InternalForceScatter<D, Taylor>& scatter, const LargeArray<SM>& S,
                            std::vector<Vec<D>>& f);
  // Traffic.hpp
  inline double gatheredBytesPerParticle() const;

  const ReferenceConfiguration<D>& ref_;
  Communicator* comm_ = nullptr;  // distributed runs only
  std::vector<Index> owned_;      // distributed: this rank's particles, ascending
  std::vector<std::vector<Index>> ownedOfMaterial_;
  std::vector<Index> ownedPassive_;
  const std::vector<Material>& materials_;
  const std::vector<double>& volume_;
  HourglassSettings hourglass_;
  std::vector<std::vector<Index>> particlesOfMaterial_;  // without the passive particles
  std::vector<Index> passive_;
  // Per particle, gathered by the pair loops at the neighbours' indices: huge pages as well.
  mutable LargeArray<Mat<D>> F_;     // (filled by observe() when !storesF())
  LargeArray<Mat<D>> P_;             // nodal quadrature only (Taylor: P + P^q)
  LargeArray<PaddedMat<D>> stress_;  // P + P^hg (energy form only; P^hg alone on the linear F)
  // 3D, energy form: u and the penalty's F padded for its pass (Padded.hpp)
  LargeArray<PaddedVec<D>> paddedU_;
  LargeArray<PaddedMat<D>> paddedPenaltyF_;
  SharedRows<Vec<D>> reverseGradient_;    // t_IJ
  SharedRows<Vec<D>> correctedGradient_;  // g_IJ (nodal quadrature, passive particles)
  SharedRows<Vec<D>> linearReverse_;      // t^lin_IJ (energy penalty on the linear F only)
  SharedRows<Vec<D>> linearGradient_;     // g^lin_IJ (the penalty's own F only)
  std::vector<Vec<D>> linearSum_;         // G^lin_I
  bool separateHourglassGradient_ = false;
  bool prefetchGathers_ = false;  // set in the constructor (and distribute())
  LargeArray<Mat<D>> hourglassF_;
  std::vector<double> hourglassStiffness_;  // K_I
  std::unique_ptr<EnergyHourglass<D>> energyHourglass_;
  std::unique_ptr<TaylorQuadrature<D>> quadrature_;
  LargeArray<PaddedMat<D>> quadratureStress_;  // P + P^q
  std::unique_ptr<GanzenmuellerHourglass<D>> ganzenmueller_;
  std::unique_ptr<ArtificialViscosity<D>> viscosity_;
  std::vector<Vec<D>> hourglassForce_;
  std::vector<Vec<D>> viscousForce_;
  // the force pass summed from its sources (InternalForceScatter), with or without Taylor
  std::unique_ptr<InternalForceScatter<D, true>> taylorScatter_;
  std::unique_ptr<InternalForceScatter<D, false>> nodalScatter_;
  bool scatter_ = true;
  mutable bool observed_ = true;  // observe() has run since the last compute()
  // The pair-loop passes' particles shared by pairs of threads that meet (MeetInTheMiddle.hpp);
  // the source-scatter force pass splits where the pass before it met.
  MeetInTheMiddle split_;
};

extern template class TlsphForces<2>;
extern template class TlsphForces<3>;

}  // namespace tlsph

#include "fast/ForcePass.hpp"
#include "fast/HourglassPass.hpp"
#include "fast/PaddedGradU.hpp"
#include "fast/StressPass.hpp"
#include "fast/Traffic.hpp"
