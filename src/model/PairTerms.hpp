// Which auxiliary pair terms a scene adds to the internal force, and how: the hourglass
// penalty (its form and the deformation gradient it compares with) and the artificial
// viscosity. TlsphForces composes the terms once; a term that is off costs nothing.
#pragma once

#include <stdexcept>
#include <string>

namespace tlsph {

// Energy: E_hg = 1/4 sum_I sum_J k_IJ |e_IJ|^2, e_IJ = x_IJ - 1/2 (F_I + F_J) X_IJ, with its
//   exact gradient (conservative, objective, zero for affine fields); docs/method.md section 2.
// Ganzenmueller: the textbook force (6.80)-(6.81), on the linear-corrected F; not the
//   gradient of an energy, so it can feed energy into undamped runs.
enum class HourglassForm { Energy, Ganzenmueller };

// The F in e_IJ: the scene's corrected one (with the quadratic correction e_IJ then
// vanishes for every quadratic field, so the penalty does not resist bending) or the
// linear-corrected (6.69) one, which resists bending in proportion to alpha.
enum class HourglassGradient { Corrected, Linear };

struct HourglassSettings {
  double alpha = 0.0;  // dimensionless; 0: no hourglass pass at all
  HourglassForm form = HourglassForm::Energy;
  HourglassGradient gradient = HourglassGradient::Corrected;
  bool enabled() const { return alpha != 0.0; }
};

// Monaghan-type artificial viscosity (6.77) in a total-Lagrangian pair form (MACHDYN's q1, q2):
// off unless a coefficient is non-zero.
struct ViscositySettings {
  double linear = 0.0;     // q1: the term proportional to c mu
  double quadratic = 0.0;  // q2: the term proportional to mu^2
  bool enabled() const { return linear != 0.0 || quadratic != 0.0; }
};

inline const char* hourglassFormName(HourglassForm f) {
  return f == HourglassForm::Energy ? "energy" : "ganzenmueller";
}
inline HourglassForm parseHourglassForm(const std::string& name) {
  if (name == "energy") return HourglassForm::Energy;
  if (name == "ganzenmueller") return HourglassForm::Ganzenmueller;
  throw std::invalid_argument("unknown hourglass form '" + name +
                              "'; expected energy or ganzenmueller");
}
inline const char* hourglassGradientName(HourglassGradient g) {
  return g == HourglassGradient::Corrected ? "corrected" : "linear";
}
inline HourglassGradient parseHourglassGradient(const std::string& name) {
  if (name == "corrected") return HourglassGradient::Corrected;
  if (name == "linear") return HourglassGradient::Linear;
  throw std::invalid_argument("unknown hourglass gradient '" + name +
                              "'; expected corrected or linear");
}

}  // namespace tlsph
