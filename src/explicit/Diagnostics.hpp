// Global quantities that tell whether a run is healthy: energies, momenta, finiteness.
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "distributed/ReproducibleSum.hpp"
#include "execution/OrderedSum.hpp"
#include "method/ReferenceConfiguration.hpp"
#include "model/Particles.hpp"
#include "model/Types.hpp"

namespace tlsph {

// Kinetic energy of the particles the integrator moves (prescribed ones are boundary).
template <int D>
double kineticEnergy(const ParticleSet<D>& p) {
  return orderedSum(p.size(), [&](Index i) {
    return p.motion[i] == Motion::Free ? 0.5 * p.mass[i] * p.velocity[i].squaredNorm() : 0.0;
  });
}

// Hourglass content of a displacement field u with displacement gradients H (H = F - 1):
//   sum_IJ W_IJ V_J |e_IJ|^2 / sum_IJ W_IJ V_J |u_I - u_J|^2,  e_IJ = u_I - u_J - 1/2 (H_I + H_J)
//   X_IJ,
// the share of the neighbours' relative displacement that the smooth field does not explain:
// 0 for affine fields (with the quadratic correction, quadratic ones), near 1 for a zig-zag.
template <int D>
// Distributed: over `particles` (a rank's own, whose pair data it keeps), summed over the ranks
// with the bits of a serial sum (ReproducibleSum.hpp).
double hourglassContent(const ReferenceConfiguration<D>& ref, const std::vector<double>& volume,
                        const std::vector<Vec<D>>& u, const std::vector<Mat<D>>& H,
                        const std::vector<Index>* particles = nullptr,
                        Communicator* comm = nullptr) {
  const auto& nb = ref.neighbours;
  const Index count = particles ? static_cast<Index>(particles->size()) : ref.particleCount();
  std::vector<double> error(static_cast<std::size_t>(count)), all(error.size());
#pragma omp parallel for schedule(static)
  for (Index p = 0; p < count; ++p) {
    const Index i = particles ? (*particles)[p] : p;
    double e = 0.0, a = 0.0;
    for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k) {
      const Index j = nb.neighbour[k];
      const double w = ref.kernelValue[k] * volume[j];
      const Vec<D> d = u[i] - u[j];
      e += w * (d - 0.5 * (H[i] + H[j]) * ref.separation[k]).squaredNorm();
      a += w * d.squaredNorm();
    }
    error[p] = e;
    all[p] = a;
  }
  const double s0 = reproducibleSum(error, comm), s1 = reproducibleSum(all, comm);
  return s1 > 0.0 ? s0 / s1 : 0.0;
}

template <int D>
Vec<D> linearMomentum(const ParticleSet<D>& p) {
  Vec<D> sum = Vec<D>::Zero();
  for (Index i = 0; i < p.size(); ++i)
    sum += p.mass[i] * p.velocity[i];
  return sum;
}

// sum_I m_I x_I x v_I about the origin; in 2D only the z component is non-zero.
template <int D>
Vec3 angularMomentum(const ParticleSet<D>& p) {
  Vec3 sum = Vec3::Zero();
  for (Index i = 0; i < p.size(); ++i) {
    Vec3 x = Vec3::Zero(), v = Vec3::Zero();
    x.head<D>() = p.currentPosition(i);
    v.head<D>() = p.velocity[i];
    sum += p.mass[i] * x.cross(v);
  }
  return sum;
}

// Torque sum_I x_I x f_I of a set of forces.
template <int D>
Vec3 totalTorque(const ParticleSet<D>& p, const std::vector<Vec<D>>& f) {
  Vec3 sum = Vec3::Zero();
  for (Index i = 0; i < p.size(); ++i) {
    Vec3 x = Vec3::Zero(), fi = Vec3::Zero();
    x.head<D>() = p.currentPosition(i);
    fi.head<D>() = f[i];
    sum += x.cross(fi);
  }
  return sum;
}

// False as soon as a displacement, velocity or force is NaN or infinite: the run has
// gone unstable and must stop with a message, not write garbage.
template <int D>
bool stateIsFinite(const ParticleSet<D>& p) {
  bool finite = true;
  const Index n = p.size();
#pragma omp parallel for reduction(&& : finite) schedule(static)
  for (Index i = 0; i < n; ++i)
    finite = finite && p.displacement[i].allFinite() && p.velocity[i].allFinite() &&
             p.force[i].allFinite();
  return finite;
}

// What one pass over the particles finds for the run's stability guards.
struct StateScan {
  Index nonFinite = -1;  // lowest-index particle with a non-finite u, v or f; -1: none
  const char* nonFiniteQuantity = "";  // "displacement", "velocity" or "force" (the first of them)
  Index smallestJParticle = -1;        // body particle with the smallest finite J = det F
  double smallestJ = std::numeric_limits<double>::infinity();
  Index fastest = -1;  // particle with the largest finite speed
  double largestSpeed = 0.0;
};

// One parallel pass: the first non-finite particle, the smallest J over the particles not
// flagged in `skip` (clamp ghosts; empty: none skipped) and the largest speed. Ties go to the
// lower index, so the result does not depend on the thread count.
template <int D>
StateScan scanState(const ParticleSet<D>& p, std::span<const Mat<D>> F,
                    const std::vector<std::uint8_t>& skip) {
  StateScan total;
  const Index n = p.size();
  auto merge = [](StateScan& into, const StateScan& s) {
    if (s.nonFinite >= 0 && (into.nonFinite < 0 || s.nonFinite < into.nonFinite)) {
      into.nonFinite = s.nonFinite;
      into.nonFiniteQuantity = s.nonFiniteQuantity;
    }
    if (s.smallestJParticle >= 0 &&
        (into.smallestJParticle < 0 || s.smallestJ < into.smallestJ ||
         (s.smallestJ == into.smallestJ && s.smallestJParticle < into.smallestJParticle))) {
      into.smallestJParticle = s.smallestJParticle;
      into.smallestJ = s.smallestJ;
    }
    if (s.fastest >= 0 && (into.fastest < 0 || s.largestSpeed > into.largestSpeed ||
                           (s.largestSpeed == into.largestSpeed && s.fastest < into.fastest))) {
      into.fastest = s.fastest;
      into.largestSpeed = s.largestSpeed;
    }
  };
#pragma omp parallel
  {
    StateScan local;
#pragma omp for schedule(static) nowait
    for (Index i = 0; i < n; ++i) {
      if (local.nonFinite < 0) {  // indices rise within a thread: the first found is its lowest
        const char* bad = !p.displacement[i].allFinite() ? "displacement"
                          : !p.velocity[i].allFinite()   ? "velocity"
                          : !p.force[i].allFinite()      ? "force"
                                                         : nullptr;
        if (bad) {
          local.nonFinite = i;
          local.nonFiniteQuantity = bad;
        }
      }
      if (skip.empty() || !skip[i]) {
        const double J = F[i].determinant();
        if (std::isfinite(J) && (local.smallestJParticle < 0 || J < local.smallestJ)) {
          local.smallestJ = J;
          local.smallestJParticle = i;
        }
      }
      const double speed = p.velocity[i].norm();
      if (std::isfinite(speed) && (local.fastest < 0 || speed > local.largestSpeed)) {
        local.largestSpeed = speed;
        local.fastest = i;
      }
    }
#pragma omp critical(tlsph_scan_state)
    merge(total, local);
  }
  return total;
}

}  // namespace tlsph
