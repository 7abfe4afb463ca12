// The highest natural frequency of a scene's discrete operator at its reference state: the
// largest eigenvalue lambda_max = omega_max^2 of K phi = lambda M phi (K the tangent stiffness
// at u = 0 on the unknowns, prescribed particles eliminated and mirrored ghosts chained; M the
// lumped masses), by Lanczos (Spectra) on M^{-1/2} K M^{-1/2} with matrix-free products.
//
// Velocity Verlet on the linearised equations is stable exactly for dt < 2 / omega_max. The
// wave-speed rule (method/TimeStep.hpp) predicts that limit from each particle's material and
// spacing, which holds on a lattice; off it a neighbourhood's gradient vectors can be several
// times longer than its spacing suggests, and only the operator itself says how fast its
// fastest mode is.
#pragma once

#include <string>

#include "method/ReferenceConfiguration.hpp"
#include "method/TimeStep.hpp"
#include "model/Scene.hpp"
#include "model/Types.hpp"

namespace tlsph {

// ref: the whole body's reference configuration (every particle with its list). Not made for
// the textbook hourglass force (not the gradient of an energy: no symmetric K) or a scene with
// nothing free to move. relativeTolerance: Lanczos' convergence bar on lambda_max.
template <int D>
SpectralEstimate highestFrequency(const Scene<D>& scene, const ReferenceConfiguration<D>& ref,
                                  double relativeTolerance = 1e-4);

extern template SpectralEstimate highestFrequency<2>(const Scene<2>&,
                                                     const ReferenceConfiguration<2>&, double);
extern template SpectralEstimate highestFrequency<3>(const Scene<3>&,
                                                     const ReferenceConfiguration<3>&, double);

}  // namespace tlsph
