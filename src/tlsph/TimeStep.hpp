// The explicit stable time step: dt = C_cfl min_I (dx_I / c_I), dx_I = V_I^(1/d),
// c the dilatational wave speed sqrt((lambda + 2 mu)/rho0) of the particle's material.
#pragma once

#include <cmath>
#include <limits>
#include <vector>

#include "materials/Material.hpp"
#include "tlsph/Particles.hpp"

namespace tlsph {

inline constexpr double kDefaultCfl = 0.3;

template <int D>
double stableTimeStep(const ParticleSet<D>& particles, const std::vector<Material>& materials,
                      double cfl) {
  std::vector<double> speed(materials.size());
  for (std::size_t m = 0; m < materials.size(); ++m)
    speed[m] = waveSpeed(materials[m]);
  double dtMin = std::numeric_limits<double>::infinity();
  for (Index i = 0; i < particles.size(); ++i) {
    const double dx = std::pow(particles.volume[i], 1.0 / D);
    dtMin = std::min(dtMin, dx / speed[particles.material[i]]);
  }
  return cfl * dtMin;
}

}  // namespace tlsph
