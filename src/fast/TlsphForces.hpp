// The per-step pair loops of total-Lagrangian SPH, read against docs/method.md section 2:
//   displacements u -> deformation gradients F (6.69) -> stresses P
//   [-> hourglass stress and spring (EnergyHourglass)] -> internal force (6.70)
//   [+ textbook hourglass pair force (6.80, 6.81)] [+ artificial viscosity (6.77)].
// The corrected gradient vectors g_IJ (ReferenceConfiguration) carry L^{-1}: with them
// F_I = 1 + sum_J (u_J - u_I) (x) g_IJ and f_I = -dE/du_I = V_I (P_I G_I - sum_J P_J t_IJ),
// which for the linear correction is (6.70): V_I sum_J V_J (B_I + B_J) gradW_IJ, B = P L^{-T}.
// Each auxiliary term is its own operator (EnergyHourglass, GanzenmuellerHourglass,
// ArtificialViscosity); the force pass is instantiated for the terms the scene uses, so a
// term that is off is not computed and the loops carry no branch on options. When the internal
// force is its only pair term, the force pass is summed from its sources
// (InternalForceScatter: the same bits, each neighbour's stress loaded once per particle).
#pragma once

#include <algorithm>
#include <cstdint>
#include <memory>
#include <span>
#include <type_traits>
#include <variant>
#include <vector>

#include "materials/Material.hpp"
#include "method/ArtificialViscosity.hpp"
#include "distributed/Communicator.hpp"
#include "fast/EnergyHourglass.hpp"
#include "method/GanzenmuellerHourglass.hpp"
#include "method/HourglassStiffness.hpp"
#include "fast/InternalForceScatter.hpp"
#include "execution/MeetInTheMiddle.hpp"
#include "execution/OrderedSum.hpp"
#include "fast/Padded.hpp"
#include "model/PairTerms.hpp"
#include "execution/Prefetch.hpp"
#include "method/ReferenceConfiguration.hpp"
#include "fast/SharedRows.hpp"
#include "fast/TaylorQuadrature.hpp"
#include "model/Types.hpp"

namespace tlsph {

template <int D>
class TlsphForces {
 public:
  TlsphForces(const ReferenceConfiguration<D>& reference, const std::vector<Material>& materials,
              const std::vector<std::uint16_t>& materialOfParticle,
              const std::vector<double>& volume, const HourglassSettings& hourglass,
              Quadrature quadrature = Quadrature::Nodal, const ViscositySettings& viscosity = {},
              double smoothingLength = 0.0, const std::vector<Index>& passive = {})
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
                                                          volume, isPassive);
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

  // A distributed run (issue 11): this rank computes the particles it owns (ascending), and
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
    padDisplacements(u);
    quadrature_ ? stressPass<true>(u) : stressPass<false>(u);
    // The penalty reads the neighbours' F (the one it compares with; padded for the energy form).
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

  // The memory traffic of one compute(), counted from the arrays the passes touch (issue 12's
  // roofline): each per-pair stream read once per pass that reads it, as stored (each distinct
  // row once, SharedRows.hpp; averaged per pair), each per-particle array read or written once
  // per pass; neighbours' values (u_J, F_J, S_J, R_J) assumed to hit the cache, so this is the
  // compulsory traffic. unsharedPerPair: the same streams stored whole. Kept next to the loops
  // it describes.
  struct Traffic {
    double perPair = 0.0;          // bytes per neighbour pair
    double perParticle = 0.0;      // bytes per particle
    double unsharedPerPair = 0.0;  // bytes per pair with every particle's rows stored
  };
  Traffic traffic() const {
    constexpr double I = sizeof(Index), V = sizeof(Vec<D>), M = sizeof(Mat<D>), d = sizeof(double);
    const TaylorQuadrature<D>* q = quadrature_.get();
    const bool taylor = q != nullptr;
    constexpr double S = sizeof(typename TaylorQuadrature<D>::Sym),
                     SM = sizeof(typename TaylorQuadrature<D>::SymMatrix),
                     PSM = sizeof(typename TaylorQuadrature<D>::PaddedSymMatrix);
    // padded (Padded.hpp): P + P^q, P + P^hg, and in 3D the penalty's u and F
    constexpr double PV = sizeof(PaddedVec<D>), PM = sizeof(PaddedMat<D>);
    const double paddedCopies = D == 3 && energyHourglass_ ? 1.0 : 0.0;
    const double pairs = std::max<double>(1.0, ref_.neighbours.pairCount());
    Traffic t;
    // each shared stream: its stored bytes once, and a row start per particle
    auto stream = [&](double storedBytes, double unsharedBytesPerPair) {
      t.perPair += storedBytes / pairs;
      t.unsharedPerPair += unsharedBytesPerPair;
      t.perParticle += I;
    };
    auto pairIndices = [&] {  // j, streamed whole
      t.perPair += I;
      t.unsharedPerPair += I;
    };
    // F pass: j and g_IJ (+ S_IJ); offset, group entry, u_I; writes F (unless only the padded
    // copy below), P (nodal) or P + P^q, the hyperstress and in 2D the second gradients (Taylor,
    // reading the particle's three constants).
    pairIndices();
    if (taylor)
      stream(q->fitRows().storedBytes(), V + S);
    else
      stream(correctedGradient_.storedBytes(), V);
    t.perParticle += 2 * I + V + (storesF() ? M : 0.0);
    t.perParticle += taylor ? PM + (D == 2 ? SM : 0.0) + PSM + 3 * d : M;
    t.perParticle += paddedCopies * PM;  // the padded F the penalty gathers
    if (separateHourglassGradient_) {    // the penalty's own F through g^lin_IJ
      pairIndices();
      stream(linearGradient_.storedBytes(), V);
      t.perParticle += I + V + M;
    }
    if (energyHourglass_) {  // j, X_IJ, c_IJ; u_I, F_I, P_I, moments, V_I; writes P + P^hg, spring
      pairIndices();
      stream(energyHourglass_->storedPairBytes(), PV + d);
      t.perParticle += paddedCopies * (V + PV);  // u padded
      t.perParticle += I;                        // the second row start
      const double P = separateHourglassGradient_ ? 0.0 : taylor ? PM : M;
      t.perParticle += I + PV + PM + P + M + V + V + PM + d;
    }
    // Force pass: j, t_IJ (+ T_IJ) (+ t^lin_IJ); S_I, G_I (+ R_I, Sum_I), V_I; writes f.
    // Summed from its sources: the records [t_IJ (+ T_IJ)] in the sources' rows, and each
    // target's sum written (its own terms) and read back (the sources' terms hit the cache).
    pairIndices();
    if (scattersInternalForce()) {
      stream(taylor ? taylorScatter_->storedPairBytes() : nodalScatter_->storedPairBytes(),
             V + (taylor ? S : 0.0));
      t.perParticle += 2 * PV;
    } else {
      stream(reverseGradient_.storedBytes(), V);
      if (taylor) stream(q->reverseRows().storedBytes(), S);
      if (separateHourglassGradient_) stream(linearReverse_.storedBytes(), V);
    }
    const bool paddedS = (energyHourglass_ && !separateHourglassGradient_) || taylor;
    t.perParticle += I + (paddedS ? PM : M) + V + (taylor ? PSM + S : 0.0) + d + V;
    if (ganzenmueller_ || viscosity_) t.perParticle += V;     // u_I for x_IJ
    if (separateHourglassGradient_) t.perParticle += PM + V;  // P^hg_I, G^lin_I
    if (energyHourglass_) t.perParticle += V;                 // the spring force
    // (the textbook form and the viscosity stream their per-pair arrays whole)
    auto whole = [&](double bytes) {
      t.perPair += bytes;
      t.unsharedPerPair += bytes;
    };
    if (ganzenmueller_) {  // X_IJ, c_IJ; F_I of the penalty; writes its force
      whole(V + d);
      t.perParticle += M + V;
    }
    if (viscosity_) {  // X_IJ (if not already), the pair's two coefficients; v_I; writes its force
      whole((ganzenmueller_ ? 0.0 : V) + 2 * d);
      t.perParticle += 2 * V;
    }
    return t;
  }

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
  // What the force pass (S_J, R_J; summed from its sources, the sums it adds to) and the
  // penalty (F_J) gather, in bytes per particle.
  double gatheredBytesPerParticle() const {
    const double force =
        scattersInternalForce()
            ? sizeof(PaddedVec<D>)
            : sizeof(PaddedMat<D>) +
                  (quadrature_ ? sizeof(typename TaylorQuadrature<D>::PaddedSymMatrix) : 0);
    return force + (energyHourglass_ ? sizeof(PaddedMat<D>) : 0);
  }

  // 3D: the F pass writes the padded F the energy penalty gathers (unless the penalty has its
  // own linear F, written by that F's pass).
  bool penaltyReadsF() const { return energyHourglass_ && !separateHourglassGradient_; }
  // Whether the F pass writes F_ itself; in 3D with the penalty on F, F lives in the padded
  // copy the penalty gathers and observe() copies it out.
  bool storesF() const { return !(D == 3 && penaltyReadsF()); }

  // Fills, once per compute() and when an observer first asks, what observers read but the
  // step does not keep (issue 12: fewer bytes written per particle-step): F_ from the penalty's
  // padded F (!storesF()) and, in 3D, the quadrature's grad grad u (recomputed from the padded
  // u with the F pass's own sums). The step's values bit for bit. From serial code only.
  void observe() const {
    if (observed_) return;
    observed_ = true;
    if constexpr (D == 3) {
      if (!storesF()) {
        const Index n = ref_.particleCount();
#pragma omp parallel for schedule(static)
        for (Index i = 0; i < n; ++i)
          F_[i] = paddedPenaltyF_[i].template topRows<D>();
      }
      if (quadrature_)
        for (const auto& group : comm_ ? ownedOfMaterial_ : particlesOfMaterial_) {
          const Index count = static_cast<Index>(group.size());
#pragma omp parallel for schedule(static)
          for (Index p = 0; p < count; ++p)
            quadrature_->keepSecondGradients(group[p], paddedU_);
        }
    }
  }

  // F_I = 1 + sum_J (u_J - u_I) (x) g_IJ (6.69), for the gradient vectors g given.
  Mat<D> deformationGradientOf(Index i, const std::vector<Vec<D>>& u,
                               const SharedRows<Vec<D>>& gradients) const {
    const auto& nb = ref_.neighbours;
    const Vec<D> ui = u[i];
    Mat<D> gradU = Mat<D>::Zero();
    const Vec<D>* g = gradients.row(i);
    const bool ahead = gradients.streams();  // SharedRows::streams
    for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k, ++g) {
      if (ahead) prefetchAhead(g);
      gradU.noalias() += (u[nb.neighbour[k]] - ui) * g->transpose();
    }
    return Mat<D>::Identity() + gradU;
  }

  // F and P of every particle (F only for the passive ones), with the quadrature's second
  // gradients in the same pass when Taylor.
  template <bool Taylor>
  void stressPass(const std::vector<Vec<D>>& u) {
    const auto& groups = comm_ ? ownedOfMaterial_ : particlesOfMaterial_;
    for (std::size_t m = 0; m < materials_.size(); ++m)
      std::visit(
          [&](const auto& model) {
            using Model = std::decay_t<decltype(model)>;
            if (D == 3 && !storesF())
              deformationAndStress<Model, Taylor, D == 3>(&model, groups[m], u);
            else
              deformationAndStress<Model, Taylor, false>(&model, groups[m], u);
          },
          materials_[m]);
    // Passive particles (mirrored ghosts): F for the penalty and the output, P stays zero.
    const auto& passive = comm_ ? ownedPassive_ : passive_;
    if (!passive.empty()) {
      if (D == 3 && !storesF())
        deformationAndStress<void, false, D == 3>(nullptr, passive, u);
      else
        deformationAndStress<void, false, false>(nullptr, passive, u);
      // their P + P^q is zero; where that is written into P + P^hg's array, clear the P^hg the
      // penalty added there last step
      if (quadrature_ && penaltyReadsF())
        for (Index i : passive)
          stress_[i].setZero();
    }
  }

  // F (and the penalty's own linear F where it has one) of the particles in group; their
  // stress P unless Model is void (the passive particles); with Taylor, P + P^q as well.
  // PaddedF: F summed padded and written only into the penalty's padded copy (!storesF(); a
  // template argument: a branch on it in the loop made GCC spill around the log call).
  template <class Model, bool Taylor, bool PaddedF>
  void deformationAndStress(const Model* model, const std::vector<Index>& group,
                            const std::vector<Vec<D>>& u) {
    const auto& nb = ref_.neighbours;
    const Index count = static_cast<Index>(group.size());
    [[maybe_unused]] TaylorQuadrature<D>* q = quadrature_.get();
    // P + P^q where the penalty adds P^hg in place, else its own array
    [[maybe_unused]] auto& taylorStress = penaltyReadsF() ? stress_ : quadratureStress_;
    constexpr Index kFitBatch = D == 3 && (Taylor || PaddedF) ? 2 : 1;
    // the fit's line ahead only where its rows stream (SharedRows::streams; a branch per pair
    // measured as slow as the prefetch itself)
    [[maybe_unused]] const bool aheadFit = Taylor && q->fitRows().streams();
    split_.reset(count);
#pragma omp parallel
    {
      MeetInTheMiddle::Chunks chunks(&split_, count);
      for (Index a, b; chunks.next(a, b);)
        for (Index p0 = a; p0 < b; p0 += kFitBatch) {
          // 3D: two particles' sums at once (TaylorQuadrature::paddedGradients, paddedGradU)
          [[maybe_unused]] typename TaylorQuadrature<D>::FitSum Ms[kFitBatch];  // [grad u | Gs]
          [[maybe_unused]] PaddedMat<D> gradUs[kFitBatch];  // 3D nodal: grad u padded
          if constexpr (Taylor && D == 3) {
            // two particles' sums, or the chunk's odd last one's
            auto sums = [&]<bool Ahead>(std::bool_constant<Ahead>) {
              if (p0 + 1 < b)
                q->template paddedGradients<Ahead>(group[p0], group[p0 + 1], paddedU_, Ms[0],
                                                   Ms[kFitBatch - 1]);
              else
                q->template paddedGradients<Ahead>(group[p0], paddedU_, Ms[0]);
            };
            aheadFit ? sums(std::true_type{}) : sums(std::false_type{});
          } else if constexpr (PaddedF) {
            if (p0 + 1 < b)
              paddedGradU(group[p0], group[p0 + 1], gradUs[0], gradUs[kFitBatch - 1]);
            else
              paddedGradU(group[p0], gradUs[0]);
          }
          for (Index p = p0; p < std::min(b, p0 + kFitBatch); ++p) {
            const Index i = group[p];
            // deformationGradientOf written out: the hot loop measured 2-3 % slower through the
            // call
            Mat<D> F;
            [[maybe_unused]] typename TaylorQuadrature<D>::SymMatrix Gs;  // 2D
            [[maybe_unused]] PaddedMat<D> Fp;                             // 3D: F padded
            if constexpr (Taylor && D == 3) {
              const auto& M = Ms[p - p0];
              Fp = padded<D, D>(Mat<D>::Identity()) + M.template leftCols<D>();  // (6.69)
              F = Fp.template topRows<D>();
            } else if constexpr (PaddedF && !Taylor) {
              const PaddedMat<D>& gradU = gradUs[p - p0];
              Fp = padded<D, D>(Mat<D>::Identity()) + gradU;  // (6.69)
              F = Fp.template topRows<D>();
            } else {
              Mat<D> gradU;
              if constexpr (Taylor) {
                q->gradients(i, u, gradU, Gs);  // grad u and grad grad u in one pass
              } else {
                const Vec<D> ui = u[i];
                gradU.setZero();
                const Vec<D>* g = correctedGradient_.row(i);
                const bool ahead = correctedGradient_.streams();
                for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k, ++g) {
                  if (ahead) prefetchAhead(g);
                  gradU.noalias() += (u[nb.neighbour[k]] - ui) * g->transpose();
                }
              }
              F = Mat<D>::Identity() + gradU;  // (6.69)
            }
            if constexpr (PaddedF)
              paddedPenaltyF_[i] = Fp;
            else
              F_[i] = F;
            if constexpr (!std::is_void_v<Model>) {
              const Mat<D> P = firstPiolaKirchhoff<D>(*model, F);
              if constexpr (!Taylor) P_[i] = P;
              if constexpr (Taylor) {
                if constexpr (D == 3)
                  q->paddedStressAt(i, Fp, Ms[p - p0], P, taylorStress[i]);
                else
                  addTop<D>(q->stressAt(i, F, Gs), P, taylorStress[i]);  // P^q + P
              }
            }
          }
        }
    }
    if (separateHourglassGradient_) {
#pragma omp parallel for schedule(static)
      for (Index p = 0; p < count; ++p) {
        const Index i = group[p];
        hourglassF_[i] = deformationGradientOf(i, u, linearGradient_);
        if constexpr (D == 3)
          if (energyHourglass_) paddedPenaltyF_[i].template topRows<D>() = hourglassF_[i];
      }
    }
  }

  // 3D nodal with the penalty on F: grad u of particles i0 and i1, the sums padded like the
  // Taylor fit's (u_J one 256-bit load, a column one 4-wide multiply-add), the two particles'
  // pairs interleaved: one particle's three column sums are chains of 4-cycle multiply-adds,
  // two particles' six keep the pipes busy (issue 12). Each column the same products in the
  // same order as the one-particle paddedGradU.
  [[gnu::always_inline]] void paddedGradU(Index i0, Index i1, PaddedMat<D>& gradU0,
                                          PaddedMat<D>& gradU1) const {
    const Index* offset = ref_.neighbours.offset.data();
    const PaddedVec<D> ui0 = paddedU_[i0], ui1 = paddedU_[i1];
    PaddedMat<D> sum0 = PaddedMat<D>::Zero(), sum1 = PaddedMat<D>::Zero();
    const Vec<D>* g0 = correctedGradient_.row(i0);
    const Vec<D>* g1 = correctedGradient_.row(i1);
    Index k0 = offset[i0], k1 = offset[i1];
    const Index end0 = offset[i0 + 1], end1 = offset[i1 + 1];
    const bool ahead = correctedGradient_.streams();
    for (const Index both = k0 + std::min(end0 - k0, end1 - k1); k0 < both; ++k0, ++k1) {
      addPaddedPair(sum0, ui0, k0, g0++, ahead);
      addPaddedPair(sum1, ui1, k1, g1++, ahead);
    }
    for (; k0 < end0; ++k0)
      addPaddedPair(sum0, ui0, k0, g0++, ahead);
    for (; k1 < end1; ++k1)
      addPaddedPair(sum1, ui1, k1, g1++, ahead);
    gradU0 = sum0;
    gradU1 = sum1;
  }
  // One particle's (the last of a chunk with an odd count).
  [[gnu::always_inline]] void paddedGradU(Index i, PaddedMat<D>& gradU) const {
    const PaddedVec<D> ui = paddedU_[i];
    PaddedMat<D> sum = PaddedMat<D>::Zero();
    const Vec<D>* g = correctedGradient_.row(i);
    const bool ahead = correctedGradient_.streams();
    for (Index k = ref_.neighbours.offset[i]; k < ref_.neighbours.offset[i + 1]; ++k)
      addPaddedPair(sum, ui, k, g++, ahead);
    gradU = sum;
  }
  // Pair k's term (u_J - u_I) (x) g_IJ of grad u, padded, g its gradient vector (ahead: the
  // rows stream, SharedRows::streams).
  [[gnu::always_inline]] void addPaddedPair(PaddedMat<D>& sum, const PaddedVec<D>& ui, Index k,
                                            const Vec<D>* g, bool ahead) const {
    if (ahead) prefetchAhead(g);
    const PaddedVec<D> du = paddedU_[ref_.neighbours.neighbour[k]] - ui;
    for (int m = 0; m < D; ++m)
      sum.col(m).noalias() += du * (*g)[m];
  }

  // The F the energy penalty gathers: in 3D a padded copy (Padded.hpp) of F or of the linear
  // F, written by the F pass; in 2D that F itself.
  LargeArray<PaddedMat<D>>& penaltyGradient() {
    if constexpr (D == 3)
      return paddedPenaltyF_;
    else
      return separateHourglassGradient_ ? hourglassF_ : F_;
  }

  // 3D: paddedU_ = u padded (the halo's as well), for the pair loops that gather it.
  void padDisplacements(const std::vector<Vec<D>>& u) {
    if constexpr (D == 3) {
      const Index n = static_cast<Index>(paddedU_.size());
#pragma omp parallel for schedule(static)
      for (Index i = 0; i < n; ++i)
        paddedU_[i].template head<D>() = u[i];
    }
  }

  // stress_ = P + P^hg (P^hg alone when P is null) and the springs (EnergyHourglass), reading
  // u and F padded in 3D (paddedU_ written at the start of compute()).
  template <class PM>
  void hourglassStress(const std::vector<Vec<D>>& u, const PM* P) {
    const std::vector<Index>* owned = comm_ ? &owned_ : nullptr;
    std::span<const PaddedVec<D>> uh;
    if constexpr (D == 3)
      uh = paddedU_;
    else
      uh = u;
    std::span<const PaddedMat<D>> F = penaltyGradient();
    if (prefetchGathers_)
      energyHourglass_->template evaluate<false, true>(uh, F, P, std::span(stress_), owned,
                                                       &split_);
    else
      energyHourglass_->evaluate(uh, F, P, std::span(stress_), owned, &split_);
  }

  // t^lin_IJ = (V_J / V_I) g^lin_JI and G^lin_I, for the energy penalty on the linear F when
  // the stress uses the quadratic correction.
  void linearReverseGradients(const std::vector<double>& volume) {
    const auto& nb = ref_.neighbours;
    linearReverse_ =
        SharedRows<Vec<D>>(nb, reverseVectors<D>(nb, ref_.linearGradient, volume, ref_.rows()));
    linearSum_.assign(ref_.particleCount(), Vec<D>::Zero());
    for (Index i = 0; i < ref_.particleCount(); ++i)
      for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k)
        linearSum_[i] += ref_.linearGradient[k];
  }

  // The force pass instantiated for the terms in use.
  template <bool Taylor>
  void forcePass(const std::vector<Vec<D>>& u, std::vector<Vec<D>>& f, const std::vector<Vec<D>>* v,
                 bool viscous) {
    prefetchGathers_ ? forcePass<Taylor, true>(u, f, v, viscous)
                     : forcePass<Taylor, false>(u, f, v, viscous);
  }
  // The stress the force pass sends through the gradient vectors: P (+ P^q), or that plus
  // P^hg (or P^hg alone through the linear vectors), padded but for P alone.
  bool forcePassStressIsPadded() const {
    return (energyHourglass_ && !separateHourglassGradient_) || quadrature_;
  }
  template <bool Taylor, bool Gather>
  void forcePass(const std::vector<Vec<D>>& u, std::vector<Vec<D>>& f, const std::vector<Vec<D>>* v,
                 bool viscous) {
    if (energyHourglass_ && !separateHourglassGradient_)
      forcePass<Taylor, Gather>(stress_, u, f, v, viscous);
    else if (Taylor)
      forcePass<Taylor, Gather>(quadratureStress_, u, f, v, viscous);
    else
      forcePass<Taylor, Gather>(P_, u, f, v, viscous);
  }
  template <bool Taylor, bool Gather, class SM>
  void forcePass(const LargeArray<SM>& S, const std::vector<Vec<D>>& u, std::vector<Vec<D>>& f,
                 const std::vector<Vec<D>>* v, bool viscous) {
    if (scattersInternalForce()) {
      if constexpr (Taylor)
        scatterForces(*taylorScatter_, S, f);
      else
        scatterForces(*nodalScatter_, S, f);
      return;
    }
    if (energyHourglass_ && separateHourglassGradient_)
      viscous ? accumulateForces<false, true, true, Taylor, Gather>(S, u, f, v)
              : accumulateForces<false, false, true, Taylor, Gather>(S, u, f, v);
    else if (ganzenmueller_)
      viscous ? accumulateForces<true, true, false, Taylor, Gather>(S, u, f, v)
              : accumulateForces<true, false, false, Taylor, Gather>(S, u, f, v);
    else
      viscous ? accumulateForces<false, true, false, Taylor, Gather>(S, u, f, v)
              : accumulateForces<false, false, false, Taylor, Gather>(S, u, f, v);
  }

  // The sums run in the padded width (Padded.hpp); an unpadded S (P alone) adds to the top D
  // rows.
  template <bool Ganzenmueller, bool Viscous, bool SeparateHourglassStress, bool Taylor,
            bool Gather, class SM>
  void accumulateForces(const LargeArray<SM>& S, const std::vector<Vec<D>>& u,
                        std::vector<Vec<D>>& f, const std::vector<Vec<D>>* velocity) {
    constexpr int R = SM::RowsAtCompileTime;
    const auto& nb = ref_.neighbours;
    // All particles, or (distributed) the owned ones.
    const Index count = comm_ ? static_cast<Index>(owned_.size()) : ref_.particleCount();
    const Index* owned = comm_ ? owned_.data() : nullptr;
    const LargeArray<Mat<D>>& Fh = separateHourglassGradient_ ? hourglassF_ : F_;
    [[maybe_unused]] const TaylorQuadrature<D>* q = quadrature_.get();
    const bool aheadT = reverseGradient_.streams();  // SharedRows::streams
    [[maybe_unused]] const bool aheadLinear = SeparateHourglassStress && linearReverse_.streams();
    [[maybe_unused]] const bool aheadTaylor = Taylor && q->reverseRows().streams();
    split_.reset(count);
#pragma omp parallel
    {
      MeetInTheMiddle::Chunks chunks(&split_, count);
      for (Index a, b; chunks.next(a, b);)
        for (Index p = a; p < b; ++p) {
          const Index i = owned ? owned[p] : p;
          // (6.70) as a force: f_I = V_I (S_I G_I - sum_J S_J t_IJ)
          PaddedVec<D> internal = PaddedVec<D>::Zero();
          internal.template head<R>().noalias() = S[i] * ref_.correctedGradientSum[i];
          Vec<D> hourglass = Vec<D>::Zero(), viscous = Vec<D>::Zero();
          const Vec<D> ui = u[i];
          if constexpr (SeparateHourglassStress) internal += stress_[i] * linearSum_[i];
          if constexpr (Taylor) internal += q->hyperForceOwn(i);  // through grad grad u
          // particle i's rows of t_IJ (and t^lin_IJ, T_IJ), advanced with k
          const Vec<D>* t = reverseGradient_.row(i);
          [[maybe_unused]] const Vec<D>* tLinear =
              SeparateHourglassStress ? linearReverse_.row(i) : nullptr;
          [[maybe_unused]] const auto* T = Taylor ? q->reverseRow(i) : nullptr;
          for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k, ++t) {
            const Index j = nb.neighbour[k];
            if (aheadT) prefetchAhead(t);
            if constexpr (Gather) prefetchGather(S.data(), j);
            internal.template head<R>().noalias() -= S[j] * *t;
            if constexpr (SeparateHourglassStress) {
              if (aheadLinear) prefetchAhead(tLinear);
              internal.noalias() -= stress_[j] * *tLinear++;
            }
            if constexpr (Taylor)
              internal.noalias() -= q->template hyperForcePair<Gather>(T++, j, aheadTaylor);
            if constexpr (Ganzenmueller || Viscous) {
              prefetchAhead(&ref_.separation[k]);
              const Vec<D>& Xij = ref_.separation[k];
              const Vec<D> xij = Xij + (ui - u[j]);
              if constexpr (Ganzenmueller)
                hourglass += ganzenmueller_->pair(k, Xij, xij, Fh[i], Fh[j]);
              if constexpr (Viscous)
                viscous += viscosity_->pair(k, xij, (*velocity)[i] - (*velocity)[j]);
            }
          }
          Vec<D> total = volume_[i] * internal.template head<D>();
          if (energyHourglass_) total += energyHourglass_->springForce(i);
          if constexpr (Ganzenmueller) {
            hourglassForce_[i] = volume_[i] * hourglass;
            total += hourglassForce_[i];
          }
          if constexpr (Viscous) {
            viscousForce_[i] = volume_[i] * viscous;
            total += viscousForce_[i];
          }
          f[i] = total;
        }
    }
  }

  // f_I = V_I (S_I G_I (+ R_I . Sum_I) - sum_J ...) + the spring, the sum over J from the
  // sources (InternalForceScatter); the own terms and the finish as accumulateForces has them.
  template <bool Taylor, class SM>
  void scatterForces(InternalForceScatter<D, Taylor>& scatter, const LargeArray<SM>& S,
                     std::vector<Vec<D>>& f) {
    constexpr int R = SM::RowsAtCompileTime;
    [[maybe_unused]] const TaylorQuadrature<D>* q = quadrature_.get();
    scatter.accumulate(
        S, Taylor ? &q->hyperstresses() : nullptr, comm_ ? &owned_ : nullptr, split_,
        [&](Index i) {
          PaddedVec<D> own = PaddedVec<D>::Zero();
          own.template head<R>().noalias() = S[i] * ref_.correctedGradientSum[i];
          if constexpr (Taylor) own += q->hyperForceOwn(i);
          return own;
        },
        [&](Index i, const PaddedVec<D>& sum) {
          Vec<D> total = volume_[i] * sum.template head<D>();
          if (energyHourglass_) total += energyHourglass_->springForce(i);
          f[i] = total;
        });
  }

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
