// JSON scalars for the small records tlsph writes (summary.json, compare results).
#pragma once

#include <cmath>
#include <string>

#include "io/RoundTripNumber.hpp"

namespace tlsph {

// A JSON string: quotes and backslashes escaped, control characters as spaces.
inline std::string jsonText(const std::string& text) {
  std::string out = "\"";
  for (char c : text) {
    if (c == '"' || c == '\\')
      out += std::string("\\") + c;
    else if (static_cast<unsigned char>(c) < 0x20)
      out += ' ';
    else
      out += c;
  }
  return out + "\"";
}

// A JSON number in shortest round-trip form; null for NaN and infinities.
inline std::string jsonNumber(double v) {
  return std::isfinite(v) ? roundTripText(v) : "null";
}

}  // namespace tlsph
