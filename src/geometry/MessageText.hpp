// Text for numbers and points in geometry error messages.
#pragma once

#include <charconv>
#include <string>
#include <string_view>

#include "model/Types.hpp"

namespace tlsph::geometry_detail {

// Shortest round-trip form ("0.1", not "0.10000000000000001"), so that two values a message
// reports as different really are different.
inline std::string numberText(double value) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  return std::string(buffer, result.ptr);
}

template <int D>
std::string pointText(const Vec<D>& x) {
  std::string text = "(";
  for (int a = 0; a < D; ++a)
    text += (a ? ", " : "") + numberText(x[a]);
  return text + ")";
}

inline std::string_view axisName(int axis) {
  constexpr std::string_view names[] = {"x", "y", "z"};
  return axis >= 0 && axis < 3 ? names[axis] : "?";
}

}  // namespace tlsph::geometry_detail
