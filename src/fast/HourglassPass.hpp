// The hourglass penalty's stress P^hg and springs, the gradient of E_hg of
// method/HourglassEnergy.hpp, added to the stress the force pass sends through the gradient
// vectors (EnergyHourglass). Members of TlsphForces (TlsphForces.hpp).
#pragma once

#include <span>
#include <vector>

#include "fast/EnergyHourglass.hpp"
#include "fast/Padded.hpp"
#include "fast/SharedRows.hpp"
#include "fast/TlsphForces.hpp"
#include "method/ReferenceConfiguration.hpp"
#include "model/Types.hpp"

namespace tlsph {

// The F the energy penalty gathers: in 3D a padded copy (Padded.hpp) of F or of the linear
// F, written by the F pass; in 2D that F itself.
template <int D>
inline LargeArray<PaddedMat<D>>& TlsphForces<D>::penaltyGradient() {
  if constexpr (D == 3)
    return paddedPenaltyF_;
  else
    return separateHourglassGradient_ ? hourglassF_ : F_;
}

// stress_ = P + P^hg (P^hg alone when P is null) and the springs (EnergyHourglass), reading
// u and F padded in 3D (paddedU_ written at the start of compute()).
template <int D>
template <class PM>
inline void TlsphForces<D>::hourglassStress(const std::vector<Vec<D>>& u, const PM* P) {
  const std::vector<Index>* owned = comm_ ? &owned_ : nullptr;
  std::span<const PaddedVec<D>> uh;
  if constexpr (D == 3)
    uh = paddedU_;
  else
    uh = u;
  std::span<const PaddedMat<D>> F = penaltyGradient();
  if (prefetchGathers_)
    energyHourglass_->template evaluate<false, true>(uh, F, P, std::span(stress_), owned, &split_);
  else
    energyHourglass_->evaluate(uh, F, P, std::span(stress_), owned, &split_);
}

// t^lin_IJ = (V_J / V_I) g^lin_JI and G^lin_I, for the energy penalty on the linear F when
// the stress uses the quadratic correction.
template <int D>
inline void TlsphForces<D>::linearReverseGradients(const std::vector<double>& volume) {
  const auto& nb = ref_.neighbours;
  linearReverse_ =
      SharedRows<Vec<D>>(nb, reverseVectors<D>(nb, ref_.linearGradient, volume, ref_.rows()));
  linearSum_.assign(ref_.particleCount(), Vec<D>::Zero());
  for (Index i = 0; i < ref_.particleCount(); ++i)
    for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k)
      linearSum_[i] += ref_.linearGradient[k];
}

}  // namespace tlsph
