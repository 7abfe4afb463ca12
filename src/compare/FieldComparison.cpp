#include "compare/FieldComparison.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace tlsph {

FieldErrors compareField(const std::string& field, int components, const std::vector<double>& value,
                         const std::vector<double>& reference,
                         const std::vector<std::uint8_t>& mask,
                         const std::vector<std::array<double, 3>>& positions) {
  const std::size_t n = mask.size();
  if (components < 1 || value.size() != n * components || reference.size() != n * components ||
      positions.size() != n)
    throw std::invalid_argument("compareField '" + field + "': " + std::to_string(value.size()) +
                                " values, " + std::to_string(reference.size()) +
                                " reference values and " + std::to_string(positions.size()) +
                                " positions for " + std::to_string(n) + " points of " +
                                std::to_string(components) + " components");
  FieldErrors e;
  e.field = field;
  e.components = components;
  double errorSquares = 0.0, referenceSquares = 0.0, maxError2 = -1.0, maxReference2 = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    if (!mask[i]) continue;
    double error2 = 0.0, reference2 = 0.0;
    for (int c = 0; c < components; ++c) {
      const double r = reference[i * components + c];
      const double d = value[i * components + c] - r;
      error2 += d * d;
      reference2 += r * r;
    }
    ++e.compared;
    errorSquares += error2;
    referenceSquares += reference2;
    // A non-finite error (an unstable run) is the largest and stays so.
    if (!std::isnan(maxError2) && !(error2 <= maxError2)) {
      maxError2 = error2;
      e.maxIndex = i;
    }
    maxReference2 = std::max(maxReference2, reference2);
  }
  if (e.compared == 0) return e;
  e.l2Relative = referenceSquares > 0.0 ? std::sqrt(errorSquares / referenceSquares) : e.kNaN;
  e.rmsAbsolute = std::sqrt(errorSquares / static_cast<double>(e.compared));
  e.maxAbsolute = std::sqrt(maxError2);
  e.maxAt = positions[e.maxIndex];
  e.maxReference = std::sqrt(maxReference2);
  e.maxRelative = maxReference2 > 0.0 ? e.maxAbsolute / e.maxReference : e.kNaN;
  return e;
}

}  // namespace tlsph
