#include "materials/ElasticConstants.hpp"

#include <charconv>
#include <cmath>
#include <system_error>

namespace tlsph {

namespace detail {

std::string formatNumber(double value) {
  // Plain decimals for the magnitudes users type (-1000000, 0.3), exponents beyond.
  const double magnitude = std::abs(value);
  const bool plain = magnitude == 0.0 || (magnitude >= 1e-4 && magnitude < 1e16);
  char buffer[64];
  const auto result =
      plain ? std::to_chars(buffer, buffer + sizeof buffer, value, std::chars_format::fixed)
            : std::to_chars(buffer, buffer + sizeof buffer, value);
  if (result.ec != std::errc()) return "?";
  return std::string(buffer, result.ptr);
}

}  // namespace detail

namespace {

using detail::formatNumber;

// "<what> = <value>", e.g. "Young's modulus E = -3".
std::string quoted(const char* what, double value) {
  return std::string(what) + " = " + formatNumber(value);
}

void requireFinite(const char* what, double value, const char* expected) {
  if (!std::isfinite(value))
    throw MaterialError(quoted(what, value) + " is not a finite number; expected " + expected);
}

void requirePositive(const char* what, double value) {
  requireFinite(what, value, "a positive number");
  if (!(value > 0.0)) throw MaterialError(quoted(what, value) + " must be positive");
}

void requirePoissonRatio(double nu) {
  requireFinite("Poisson's ratio nu", nu, "a value in the range (-1, 0.5)");
  if (!(nu > -1.0 && nu < 0.5)) {
    std::string message =
        quoted("Poisson's ratio nu", nu) + " is outside the allowed range (-1, 0.5)";
    if (nu == 0.5)
      message +=
          " (nu = 0.5 is incompressible, which this compressible explicit solver cannot "
          "represent; use e.g. 0.49)";
    throw MaterialError(message);
  }
}

// The factories' common last step: a huge but finite input can still overflow a derived
// constant (e.g. lambda for nu -> 0.5), and NaN must never leave a factory.
ElasticConstants checked(const ElasticConstants& c) {
  const double all[] = {c.lambda,       c.mu,          c.youngsModulus,
                        c.poissonRatio, c.bulkModulus, c.pWaveModulus()};
  for (double v : all)
    if (!std::isfinite(v))
      throw MaterialError(
          "elastic constants out of floating-point range: lambda = " + formatNumber(c.lambda) +
          ", mu = " + formatNumber(c.mu) + ", E = " + formatNumber(c.youngsModulus) +
          ", nu = " + formatNumber(c.poissonRatio) + ", K = " + formatNumber(c.bulkModulus));
  return c;
}

}  // namespace

ElasticConstants ElasticConstants::fromYoungPoisson(double E, double nu) {
  requirePositive("Young's modulus E", E);
  requirePoissonRatio(nu);
  ElasticConstants c;
  c.youngsModulus = E;
  c.poissonRatio = nu;
  c.mu = E / (2.0 * (1.0 + nu));
  c.lambda = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
  c.bulkModulus = E / (3.0 * (1.0 - 2.0 * nu));
  return checked(c);
}

ElasticConstants ElasticConstants::fromLame(double lambda, double mu) {
  requireFinite("Lame parameter lambda", lambda, "a real number greater than -2 mu / 3");
  requirePositive("shear modulus (Lame parameter) mu", mu);
  // With mu > 0, -1 < nu < 0.5  <=>  K = lambda + 2 mu / 3 > 0.
  const double K = lambda + 2.0 * mu / 3.0;
  if (!(K > 0.0))
    throw MaterialError(quoted("Lame parameter lambda", lambda) + " with mu = " + formatNumber(mu) +
                        " gives bulk modulus K = lambda + 2 mu / 3 = " + formatNumber(K) +
                        ", which must be positive (Poisson's ratio nu = lambda / (2 (lambda + "
                        "mu)) must lie in (-1, 0.5)); require lambda > " +
                        formatNumber(-2.0 * mu / 3.0));
  ElasticConstants c;
  c.lambda = lambda;
  c.mu = mu;
  c.bulkModulus = K;
  c.youngsModulus = mu * (3.0 * lambda + 2.0 * mu) / (lambda + mu);
  c.poissonRatio = lambda / (2.0 * (lambda + mu));
  return checked(c);
}

ElasticConstants ElasticConstants::fromShearBulk(double mu, double K) {
  requirePositive("shear modulus mu", mu);
  requirePositive("bulk modulus K", K);
  ElasticConstants c;
  c.mu = mu;
  c.bulkModulus = K;
  c.lambda = K - 2.0 * mu / 3.0;
  c.youngsModulus = 9.0 * K * mu / (3.0 * K + mu);
  c.poissonRatio = (3.0 * K - 2.0 * mu) / (2.0 * (3.0 * K + mu));
  return checked(c);
}

void validateDensity(double rho0) {
  requirePositive("density rho0", rho0);
}

}  // namespace tlsph
