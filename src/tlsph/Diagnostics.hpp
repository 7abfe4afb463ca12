// Global quantities that tell whether a run is healthy: energies, momenta, finiteness.
#pragma once

#include "tlsph/Particles.hpp"
#include "tlsph/Types.hpp"

namespace tlsph {

// Kinetic energy of the particles the integrator moves (prescribed ones are boundary).
template <int D>
double kineticEnergy(const ParticleSet<D>& p) {
  double sum = 0.0;
  const Index n = p.size();
#pragma omp parallel for reduction(+ : sum) schedule(static)
  for (Index i = 0; i < n; ++i)
    if (p.motion[i] == Motion::Free) sum += 0.5 * p.mass[i] * p.velocity[i].squaredNorm();
  return sum;
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

}  // namespace tlsph
