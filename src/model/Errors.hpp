// Errors a user can act on: the message says what is wrong and where.
#pragma once

#include <stdexcept>

namespace tlsph {

// A scene that cannot be simulated as set up (too few neighbours, ill-conditioned
// correction tensor, periodic box too small for the kernel support, ...).
class SetupError : public std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace tlsph
