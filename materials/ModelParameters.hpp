// The data every material model carries: its small-strain constants and reference density.
#pragma once

#include <cmath>

#include "materials/ElasticConstants.hpp"

namespace tlsph {

// Non-virtual base of the models (no dynamic dispatch anywhere in the library).
class ModelParameters {
 public:
  // Validates the density; the constants are valid by construction (see the factories).
  ModelParameters(const ElasticConstants& c, double density) : constants_(c), density_(density) {
    validateDensity(density);
  }

  const ElasticConstants& constants() const { return constants_; }
  double density() const { return density_; }
  // Small-strain P-wave speed sqrt((lambda + 2 mu) / rho0), used by the time-step rule.
  double waveSpeed() const { return std::sqrt(constants_.pWaveModulus() / density_); }

 private:
  ElasticConstants constants_;
  double density_;
};

}  // namespace tlsph
