// Error norms of one field between tlsph and a reference solution, on plain arrays: the
// numbers `tlsph compare` reports.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace tlsph {

struct FieldErrors {
  static constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

  std::string field;
  int components = 0;
  std::size_t compared = 0;  // points with mask != 0
  // Relative L2 error sqrt(sum |e_I|^2 / sum |ref_I|^2) over the compared points, e = value -
  // reference, unweighted (tlsph particles of a scene share one volume dx^d, so this is the
  // volume-weighted norm); NaN if the reference is zero at every compared point.
  double l2Relative = kNaN;
  double rmsAbsolute = kNaN;                      // sqrt(mean |e_I|^2)
  double maxAbsolute = kNaN;                      // max |e_I|
  std::size_t maxIndex = 0;                       // the point where it occurs (first of equals)
  std::array<double, 3> maxAt{kNaN, kNaN, kNaN};  // its position
  double maxReference = kNaN;                     // max |ref_I|
  double maxRelative = kNaN;  // maxAbsolute / maxReference; NaN if maxReference = 0
};

// Compares `value` with `reference` (both `components` values per point, point-major) over
// the points with mask[I] != 0; |.| is the Euclidean norm of a point's components (for a
// tensor the Frobenius norm). positions[I] is only reported (maxAt). With no compared point,
// every number is NaN. Throws std::invalid_argument if the array sizes disagree.
FieldErrors compareField(const std::string& field, int components, const std::vector<double>& value,
                         const std::vector<double>& reference,
                         const std::vector<std::uint8_t>& mask,
                         const std::vector<std::array<double, 3>>& positions);

}  // namespace tlsph
