// Everything a total-Lagrangian step needs from the reference configuration, computed once:
// neighbour lists, per-pair kernel data and the inverse correction tensors L_I^{-1}.
#pragma once

#include <vector>

#include "tlsph/Kernel.hpp"
#include "tlsph/NeighbourList.hpp"
#include "tlsph/PeriodicBox.hpp"
#include "tlsph/Types.hpp"

namespace tlsph {

template <int D>
struct ReferenceConfiguration {
  NeighbourList neighbours;
  // Per pair (I, J), in CSR order:
  std::vector<Vec<D>> separation;        // X_IJ = X_I - X_J (minimum image)
  std::vector<Vec<D>> weightedGradient;  // w_IJ = V_J gradW_IJ
  std::vector<double> kernelValue;       // W(X_IJ)
  // Per particle:
  std::vector<Mat<D>> correctionInverse;  // L_I^{-1}, (6.44)
  std::vector<Vec<D>> gradientSum;        // s_I = sum_J w_IJ

  Index particleCount() const { return neighbours.particleCount(); }
};

// Smallest accepted reciprocal condition number of L_I (sigma_min / sigma_max).
inline constexpr double kDefaultMinCorrectionCondition = 1e-6;

// Throws SetupError naming the particle whose L_I is singular or badly conditioned.
template <int D>
ReferenceConfiguration<D> buildReferenceConfiguration(
    const std::vector<Vec<D>>& X, const std::vector<double>& volume, const Kernel<D>& kernel,
    const PeriodicBox<D>& box = {}, double minCorrectionCondition = kDefaultMinCorrectionCondition);

}  // namespace tlsph
