// The explicit stable time step (docs/method.md section 2):
//   dt = C_cfl min_I dx_I / c_eff,I,   c_eff,I^2 = c_I^2 + c_hg,I^2,
// dx_I = (mean of V_J over I and its neighbours)^(1/d), the spacing of I's neighbourhood: the
// pair force on I scales with V_I like its mass, so I's acceleration is set by its neighbours'
// spacing and the kernel, not by its own cell (a small cell among normal ones, as meshes give
// at edges, does not make the operator faster); on a lattice it is V_I^(1/d). c_I = sqrt((lambda +
// 2 mu)/rho0) of the particle's material, and c_hg,I^2 = kappa dx_I^2 K_I / m_I the speed the
// hourglass penalty adds, K_I = sum_J k_IJ its spring stiffness at I. kappa = 1/2 would be the
// Gershgorin bound of the spring network alone; it overstates the fastest mode of penalty plus
// material several-fold, and kappa = 1/16 is what the measured limits give (undamped 3D cantilever,
// 2D plate, quadratic correction, energy penalty; limits in C of dx/c: alpha 0: 0.51 / 0.55, alpha
// 10: 0.49 / 0.55, alpha 100: 0.27 / 0.35), so the rule's critical C stays near 0.5 for alpha from
// 0 to 100 (validation/stability maps it). Only particles the integrator moves count.
#pragma once

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "materials/Material.hpp"
#include "method/NeighbourList.hpp"
#include "model/Particles.hpp"

namespace tlsph {

inline constexpr double kDefaultCfl = 0.3;
inline constexpr double kHourglassSpeedFactor = 1.0 / 16.0;  // kappa

struct StableStep {
  double dt = 0.0;
  Index particle = -1;          // the particle that sets it
  double dx = 0.0;              // its neighbourhood's spacing
  double waveSpeed = 0.0;       // its material's c
  double hourglassSpeed = 0.0;  // its c_hg
  // The penalty raises the effective wave speed at the limiting particle by this factor.
  double hourglassFactor() const {
    return waveSpeed > 0.0 ? std::sqrt(1.0 + std::pow(hourglassSpeed / waveSpeed, 2)) : 1.0;
  }
};

// dx_I for each particle with a list in nb (the others: V_I^(1/d)). Written as V_I plus the mean
// difference so that equal volumes give V_I^(1/d) to the bit.
template <int D>
std::vector<double> neighbourhoodSpacing(const NeighbourList& nb,
                                         const std::vector<double>& volume) {
  std::vector<double> dx(volume.size());
  for (Index i = 0; i < static_cast<Index>(volume.size()); ++i) {
    double difference = 0.0;
    const Index n = i < nb.particleCount() ? nb.count(i) : 0;
    for (Index k = 0; k < n; ++k)
      difference += volume[nb.neighbour[nb.offset[i] + k]] - volume[i];
    dx[i] = std::pow(volume[i] + difference / double(n + 1), 1.0 / D);
  }
  return dx;
}

// hourglassStiffness: K_I per particle, or empty when the penalty is off.
// candidates: only these particles (ascending; a rank's own, whose stiffness it knows), else
// all. spacing: dx_I per particle (neighbourhoodSpacing), or empty for V_I^(1/d).
template <int D>
StableStep stableStep(const ParticleSet<D>& particles, const std::vector<Material>& materials,
                      double cfl, const std::vector<double>& hourglassStiffness = {},
                      const std::vector<Index>* candidates = nullptr,
                      const std::vector<double>& spacing = {}) {
  std::vector<double> speed(materials.size());
  for (std::size_t m = 0; m < materials.size(); ++m)
    speed[m] = waveSpeed(materials[m]);
  bool anyFree = false;
  for (Index i = 0; i < particles.size() && !anyFree; ++i)
    anyFree = particles.motion[i] == Motion::Free;
  StableStep best;
  double bestRatio = std::numeric_limits<double>::infinity();
  const Index count = candidates ? static_cast<Index>(candidates->size()) : particles.size();
  for (Index q = 0; q < count; ++q) {
    const Index i = candidates ? (*candidates)[q] : q;
    if (anyFree && particles.motion[i] != Motion::Free) continue;
    const double dx = spacing.empty() ? std::pow(particles.volume[i], 1.0 / D) : spacing[i];
    const double c = speed[particles.material[i]];
    const double chg2 = hourglassStiffness.empty() ? 0.0
                                                   : kHourglassSpeedFactor * dx * dx *
                                                         hourglassStiffness[i] / particles.mass[i];
    const double ratio = dx / std::sqrt(c * c + chg2);
    if (ratio < bestRatio) {
      bestRatio = ratio;
      best = {cfl * ratio, i, dx, c, std::sqrt(chg2)};
    }
  }
  return best;
}

// The operator's own limit (modes/HighestFrequency.hpp): velocity Verlet on the linearised
// equations is stable for dt < 2 / omega_max, omega_max^2 the largest eigenvalue of M^-1 K. The
// step is kept within kSpectralStepFraction of it. On a lattice the rule above at the default
// C_cfl = 0.3 sits at 43-67 % of the measured limits (C = 0.45-0.7), so the cap leaves it alone;
// it binds where the operator is stiffer than each particle's spacing and wave speed predict
// (particles off the lattice), and the margin covers stiffening under large deformation.
inline constexpr double kSpectralStepFraction = 0.8;

// lambdaMax = omega_max^2 [1/s^2]; infinity when there is none.
inline double spectralStepLimit(double lambdaMax) {
  return lambdaMax > 0.0 ? kSpectralStepFraction * 2.0 / std::sqrt(lambdaMax)
                         : std::numeric_limits<double>::infinity();
}

// The operator's highest frequency at the reference state (modes/HighestFrequency.hpp).
struct SpectralEstimate {
  bool made = false;    // an estimate was made (else `why`)
  std::string why;      // completes "no spectral limit: "
  double lambda = 0.0;  // omega_max^2 [1/s^2]
  Index particle = -1;  // the largest amplitude in the fastest mode (where the stiffness sits)
  int products = 0;     // products K v the estimate took
  double seconds = 0.0;
  // Velocity Verlet's critical step 2 / omega_max (0 when not made).
  double criticalStep() const { return made && lambda > 0.0 ? 2.0 / std::sqrt(lambda) : 0.0; }
};

// The cap as a run applies it.
struct SpectralStep : SpectralEstimate {
  double limit = std::numeric_limits<double>::infinity();  // spectralStepLimit(lambda)
  bool binds = false;  // the run's step is the cap, not the rule
};

template <int D>
double stableTimeStep(const ParticleSet<D>& particles, const std::vector<Material>& materials,
                      double cfl, const std::vector<double>& hourglassStiffness = {}) {
  return stableStep(particles, materials, cfl, hourglassStiffness).dt;
}

}  // namespace tlsph
