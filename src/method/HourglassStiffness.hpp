// The hourglass penalty's pair coefficient of (6.80):
//   c_IJ = alpha (E_I + E_J)/2 V_J W(X_IJ) / |X_IJ|^2,
// so that k_IJ = V_I c_IJ = alpha E_IJ V_I V_J W / |X_IJ|^2 is symmetric in I and J (pair forces
// stay balanced across material interfaces). Depends on the reference configuration only.
// Passive particles (mirrored ghosts, which carry no energy of their own) count half in a
// pair with a body particle and not at all with each other: the weight (w_I + w_J)/2 keeps
// k_IJ symmetric.
#pragma once

#include <cstdint>
#include <vector>

#include "materials/Material.hpp"
#include "method/ReferenceConfiguration.hpp"

namespace tlsph {

template <int D>
PairArray<double> hourglassPairCoefficients(const ReferenceConfiguration<D>& ref,
                                            const std::vector<Material>& materials,
                                            const std::vector<std::uint16_t>& materialOf,
                                            const std::vector<double>& volume, double alpha,
                                            const std::vector<std::uint8_t>& passive = {}) {
  const auto& nb = ref.neighbours;
  std::vector<double> youngs(materials.size());
  for (std::size_t m = 0; m < materials.size(); ++m)
    youngs[m] = elasticConstants(materials[m]).youngsModulus;
  PairArray<double> c(nb.pairCount());
  for (Index i = 0; i < ref.particleCount(); ++i)
    for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k) {
      const Index j = nb.neighbour[k];
      const double E = 0.5 * (youngs[materialOf[i]] + youngs[materialOf[j]]);
      c[k] = alpha * E * volume[j] * ref.kernelValue[k] / ref.separation[k].squaredNorm();
      if (!passive.empty()) c[k] *= 1.0 - 0.5 * (passive[i] + passive[j]);
    }
  return c;
}

// K_I = sum_J k_IJ = V_I sum_J c_IJ: the penalty's spring stiffness at each particle (for the
// stable time step).
template <int D>
std::vector<double> hourglassParticleStiffness(const ReferenceConfiguration<D>& ref,
                                               const PairArray<double>& c,
                                               const std::vector<double>& volume) {
  const auto& nb = ref.neighbours;
  std::vector<double> K(ref.particleCount(), 0.0);
  for (Index i = 0; i < ref.particleCount(); ++i) {
    for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k)
      K[i] += c[k];
    K[i] *= volume[i];
  }
  return K;
}

}  // namespace tlsph
