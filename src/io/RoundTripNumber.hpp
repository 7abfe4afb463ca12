// Text for doubles that reads back to the identical value, as short as possible.
#pragma once

#include <string>

namespace tlsph {

// Shortest decimal form that round-trips through std::stod / strtod ("0.1", "1e-05",
// "nan", "inf"): output files must not lose precision, and need not be padded to 17 digits.
std::string roundTripText(double value);

}  // namespace tlsph
