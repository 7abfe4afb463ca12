// The internal force (6.70), as method/InternalForce.hpp, f_I = V_I (S_I G_I - sum_J S_J t_IJ)
// with S the stress of the terms in use, plus the pair forces of the textbook hourglass
// (6.80, 6.81) and the artificial viscosity (6.77): gathered, or summed from the sources
// (InternalForceScatter) when the internal force is the only pair term. Members of TlsphForces
// (TlsphForces.hpp).
#pragma once

#include <vector>

#include "execution/MeetInTheMiddle.hpp"
#include "execution/Prefetch.hpp"
#include "fast/InternalForceScatter.hpp"
#include "fast/Padded.hpp"
#include "fast/TaylorQuadrature.hpp"
#include "fast/TlsphForces.hpp"
#include "model/Types.hpp"

namespace tlsph {

// The force pass instantiated for the terms in use.
template <int D>
template <bool Taylor>
inline void TlsphForces<D>::forcePass(const std::vector<Vec<D>>& u, std::vector<Vec<D>>& f,
                                      const std::vector<Vec<D>>* v, bool viscous) {
  prefetchGathers_ ? forcePass<Taylor, true>(u, f, v, viscous)
                   : forcePass<Taylor, false>(u, f, v, viscous);
}

template <int D>
template <bool Taylor, bool Gather>
inline void TlsphForces<D>::forcePass(const std::vector<Vec<D>>& u, std::vector<Vec<D>>& f,
                                      const std::vector<Vec<D>>* v, bool viscous) {
  if (energyHourglass_ && !separateHourglassGradient_)
    forcePass<Taylor, Gather>(stress_, u, f, v, viscous);
  else if (Taylor)
    forcePass<Taylor, Gather>(quadratureStress_, u, f, v, viscous);
  else
    forcePass<Taylor, Gather>(P_, u, f, v, viscous);
}

template <int D>
template <bool Taylor, bool Gather, class SM>
inline void TlsphForces<D>::forcePass(const LargeArray<SM>& S, const std::vector<Vec<D>>& u,
                                      std::vector<Vec<D>>& f, const std::vector<Vec<D>>* v,
                                      bool viscous) {
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
template <int D>
template <bool Ganzenmueller, bool Viscous, bool SeparateHourglassStress, bool Taylor, bool Gather,
          class SM>
inline void TlsphForces<D>::accumulateForces(const LargeArray<SM>& S, const std::vector<Vec<D>>& u,
                                             std::vector<Vec<D>>& f,
                                             const std::vector<Vec<D>>* velocity) {
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
template <int D>
template <bool Taylor, class SM>
inline void TlsphForces<D>::scatterForces(InternalForceScatter<D, Taylor>& scatter,
                                          const LargeArray<SM>& S, std::vector<Vec<D>>& f) {
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

}  // namespace tlsph
