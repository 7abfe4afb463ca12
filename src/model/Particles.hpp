// Particle storage as a structure of arrays: one contiguous array per field.
#pragma once

#include <cstdint>
#include <vector>

#include "model/QuadratureMoments.hpp"
#include "model/Types.hpp"

namespace tlsph {

// How a particle moves: by the integrator, by a prescription (fixed clamps, driven
// boundaries), or as the odd mirror image of a body particle (mirrored clamp ghosts: u = -u_M).
// Prescribed and mirrored particles take part in every neighbour sum.
enum class Motion : std::uint8_t { Free, Prescribed, Mirrored };

template <int D>
struct ParticleSet {
  std::vector<Vec<D>> referencePosition;  // X_I
  std::vector<Vec<D>> displacement;       // u_I, x_I = X_I + u_I
  std::vector<Vec<D>> velocity;           // v_I
  std::vector<Vec<D>> force;              // total force on I (internal + hourglass + external)
  std::vector<double> volume;             // V_I (area per unit thickness in 2D)
  std::vector<double> mass;               // m_I = rho0 V_I
  std::vector<std::uint16_t> material;    // index into the scene's materials
  std::vector<Motion> motion;
  // The quadrature moments of each particle's weight (QuadratureMoments.hpp), mu_I and N_I.
  // Empty: every particle is the centre of its lattice cell (mu = 0, N = l^2/12 1). A body
  // meshed from a file sets them; particles added after that get their lattice cell's.
  std::vector<Vec<D>> quadratureOffset;
  std::vector<Mat<D>> quadratureSpread;
  // a_I = int lambda_I n dA over the body's whole boundary, for the integration constraint
  // (method/IntegrationConstraint.hpp). Empty: not known (lattice bodies, particle files), and
  // the gradient vectors stay as fitted. A body meshed from a file sets it and is the scene's
  // only body.
  std::vector<Vec<D>> boundaryArea;
  // b_I = int lambda_I (X - X_I) (x) n dA over the same boundary, for the linear-stress
  // constraint only (geometry/BoundaryArea.hpp); empty otherwise.
  std::vector<Mat<D>> boundaryMoment;

  Index size() const { return static_cast<Index>(referencePosition.size()); }

  Index add(const Vec<D>& X, double V, double m, std::uint16_t materialIndex,
            Motion how = Motion::Free) {
    referencePosition.push_back(X);
    displacement.push_back(Vec<D>::Zero());
    velocity.push_back(Vec<D>::Zero());
    force.push_back(Vec<D>::Zero());
    volume.push_back(V);
    mass.push_back(m);
    material.push_back(materialIndex);
    motion.push_back(how);
    if (!quadratureOffset.empty()) {
      quadratureOffset.push_back(Vec<D>::Zero());
      quadratureSpread.push_back(latticeSpread<D>(V));
    }
    if (!boundaryArea.empty()) boundaryArea.push_back(Vec<D>::Zero());
    if (!boundaryMoment.empty()) boundaryMoment.push_back(Mat<D>::Zero());
    return size() - 1;
  }

  QuadratureMoments<D> quadratureMoments() const { return {quadratureOffset, quadratureSpread}; }

  Vec<D> currentPosition(Index i) const { return referencePosition[i] + displacement[i]; }
};

}  // namespace tlsph
