// Isotropic small-strain elastic constants and the validation of material parameters.
// Every model is parameterised by one ElasticConstants value (plus a density); the
// constants also give the wave speed of the time-step rule and E of the hourglass term.
#pragma once

#include <limits>
#include <stdexcept>
#include <string>

namespace tlsph {

// An invalid material parameter. The message names the parameter, the value given and
// the allowed range, so it can be shown to the user as is.
class MaterialError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

// The five 3D isotropic constants, always mutually consistent:
//   mu = E / (2 (1 + nu)),  lambda = E nu / ((1 + nu)(1 - 2 nu)),  K = lambda + 2 mu / 3.
// Build it with one of the factories, which validate their input (-1 < nu < 0.5 and
// positive E, mu, K); a default-constructed value holds NaNs.
struct ElasticConstants {
  double lambda = std::numeric_limits<double>::quiet_NaN();  // Lame's first parameter
  double mu = std::numeric_limits<double>::quiet_NaN();      // shear modulus
  double youngsModulus = std::numeric_limits<double>::quiet_NaN();
  double poissonRatio = std::numeric_limits<double>::quiet_NaN();
  double bulkModulus = std::numeric_limits<double>::quiet_NaN();

  static ElasticConstants fromYoungPoisson(double E, double nu);
  static ElasticConstants fromLame(double lambda, double mu);
  static ElasticConstants fromShearBulk(double mu, double K);

  // lambda + 2 mu: the modulus of a longitudinal (P) wave, c = sqrt(M / rho0).
  double pWaveModulus() const { return lambda + 2 * mu; }
};

// Throws MaterialError unless rho0 is finite and positive.
void validateDensity(double rho0);

namespace detail {
// Shortest text that reads back as the same double, in plain decimals where readable
// ("0.5", "-3", "2000000", "1e-07", "nan", "inf").
std::string formatNumber(double value);
}  // namespace detail

}  // namespace tlsph
