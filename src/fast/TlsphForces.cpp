// The force of method/InternalForce.hpp (TlsphForces.hpp) compiled once for 2D and 3D, in a
// unit of its own: the hot pair loops are then
// optimised the same way whatever file uses them (in a large unit GCC had stopped inlining
// Eigen's small products inside EnergyHourglass::evaluate, 20 % slower).
#ifndef EIGEN_STRONG_INLINE
#define EIGEN_STRONG_INLINE inline __attribute__((always_inline))
#endif
#include "fast/TlsphForces.hpp"

namespace tlsph {

template class TlsphForces<2>;
template class TlsphForces<3>;

}  // namespace tlsph
