// Artificial viscosity (6.77) in a total-Lagrangian pair form, Monaghan's linear and quadratic
// terms (MACHDYN's q1, q2), for impact and wave scenes:
//   mu_IJ = h v_IJ . x_IJ / (|x_IJ|^2 + 0.01 h^2)            (approaching pairs only, mu < 0)
//   Pi_IJ = (-q1 c_IJ mu_IJ + q2 mu_IJ^2) / rho_IJ
//   f_I  = -sum_J m_I m_J Pi_IJ W'(|X_IJ|) x_IJ/|x_IJ|
// with the kernel slope of the reference configuration, mean wave speed c_IJ and mean
// reference density rho_IJ. A central, antisymmetric pair force along the current separation:
// it conserves linear and angular momentum and only ever removes energy.
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include "materials/Material.hpp"
#include "method/ReferenceConfiguration.hpp"
#include "model/PairTerms.hpp"

namespace tlsph {

template <int D>
class ArtificialViscosity {
 public:
  ArtificialViscosity(const ReferenceConfiguration<D>& ref, const std::vector<Material>& materials,
                      const std::vector<std::uint16_t>& materialOf, double smoothingLength,
                      const ViscositySettings& settings)
      : h_(smoothingLength), q1_(settings.linear), q2_(settings.quadratic) {
    const auto& nb = ref.neighbours;
    weight_.resize(nb.pairCount());
    speed_.resize(nb.pairCount());
    for (Index i = 0; i < ref.particleCount(); ++i)
      for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k) {
        const Index j = nb.neighbour[k];
        const double ri = density(materials[materialOf[i]]);
        const double rj = density(materials[materialOf[j]]);
        // m_I m_J / rho_IJ = V_I * [V_J rho_I rho_J / rho_IJ]; |w_IJ| = V_J |W'|
        weight_[k] = (ri * rj / (0.5 * (ri + rj))) * ref.weightedGradient[k].norm();
        speed_[k] =
            0.5 * (waveSpeed(materials[materialOf[i]]) + waveSpeed(materials[materialOf[j]]));
      }
  }

  // The pair's contribution to f_I / V_I.
  Vec<D> pair(Index k, const Vec<D>& xij, const Vec<D>& vij) const {
    const double approach = vij.dot(xij);
    if (approach >= 0.0) return Vec<D>::Zero();
    const double r2 = xij.squaredNorm();
    const double mu = h_ * approach / (r2 + 0.01 * h_ * h_);
    // m_I m_J Pi_IJ |W'| / V_I = weight_ (-q1 c mu + q2 mu^2): pushes approaching pairs apart
    return (weight_[k] * (-q1_ * speed_[k] * mu + q2_ * mu * mu) / std::sqrt(r2)) * xij;
  }

 private:
  double h_, q1_, q2_;
  PairArray<double> weight_;  // V_J rho_I rho_J / rho_IJ |W'(X_IJ)|
  PairArray<double> speed_;   // c_IJ
};

}  // namespace tlsph
