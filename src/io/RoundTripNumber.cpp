#include "io/RoundTripNumber.hpp"

#include <array>
#include <charconv>

namespace tlsph {

std::string roundTripText(double value) {
  std::array<char, 32> buffer;  // the longest shortest form of a double is 24 characters
  const auto result = std::to_chars(buffer.data(), buffer.data() + buffer.size(), value);
  return std::string(buffer.data(), result.ptr);
}

}  // namespace tlsph
