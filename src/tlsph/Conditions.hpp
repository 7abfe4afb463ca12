// Boundary conditions, loads and damping (chapter section 6.11; DESIGN.md section 3).
#pragma once

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "tlsph/Types.hpp"

namespace tlsph {

// A linear ramp from 0 at t = 0 to 1 at t = duration; duration 0 means "on from the start".
struct Ramp {
  double duration = 0.0;
  double factor(double t) const {
    return duration > 0.0 ? std::clamp(t / duration, 0.0, 1.0) : 1.0;
  }
  double rate(double t) const { return duration > 0.0 && t < duration ? 1.0 / duration : 0.0; }
};

enum class PrescribedMotion {
  Fixed,         // u stays where it starts
  Velocity,      // v = value * ramp(t)
  Displacement,  // u = u0 + value * ramp(t)
  Rotation,      // rigid rotation about an axis through a point, rate * ramp(t) [rad/s]
};

// Angle swept by the rate `rate * ramp.factor(t)` from 0 to t, exactly: with a ramp of
// duration T, rate t^2 / (2 T) for t < T, then rate (t - T / 2).
inline double rampedAngle(double rate, const Ramp& ramp, double t) {
  if (t <= 0.0) return 0.0;
  const double T = ramp.duration;
  if (T <= 0.0) return rate * t;
  return t < T ? rate * t * t / (2.0 * T) : rate * (t - 0.5 * T);
}

// Rotation by theta about the unit vector `axis` (Rodrigues); in 2D about z, `axis` is +z or
// -z (the sense).
template <int D>
Mat<D> rotationMatrix(const Vec3& axis, double theta) {
  if constexpr (D == 2) theta *= axis.z() < 0.0 ? -1.0 : 1.0;
  const double c = std::cos(theta), s = std::sin(theta);
  if constexpr (D == 2) {
    Mat<2> R;
    R << c, -s, s, c;
    return R;
  } else {
    Mat3 K;
    K << 0.0, -axis.z(), axis.y(), axis.z(), 0.0, -axis.x(), -axis.y(), axis.x(), 0.0;
    return c * Mat3::Identity() + s * K + (1.0 - c) * axis * axis.transpose();
  }
}

// Velocity omega axis x r of a rigid rotation; in 2D about +z or -z.
template <int D>
Vec<D> rotationVelocity(const Vec3& axis, double omega, const Vec<D>& r) {
  if constexpr (D == 2) {
    if (axis.z() < 0.0) omega = -omega;
    return Vec<2>(-omega * r.y(), omega * r.x());
  } else {
    return omega * axis.cross(r);
  }
}

// Dirichlet condition on a group of particles (ghost clamps are Fixed groups).
template <int D>
struct Prescription {
  std::string name;
  std::vector<Index> particles;
  PrescribedMotion motion = PrescribedMotion::Fixed;
  Vec<D> value = Vec<D>::Zero();
  Ramp ramp;
  // Rotation: x(t) = point + R(theta(t)) (x_start - point), theta = rampedAngle(rate, ramp, t),
  // v = rate ramp(t) axis x (x - point). `axis` is a unit vector (3D; 2D rotates about z).
  Vec3 axis = Vec3::UnitZ();
  Vec<D> point = Vec<D>::Zero();
  double rate = 0.0;
};

// Neumann condition: a force per particle at full value (a traction already multiplied by
// the particle's area, or a total force already shared out), scaled by the ramp.
template <int D>
struct Load {
  std::string name;
  std::vector<Index> particles;
  std::vector<Vec<D>> force;
  Ramp ramp;
};

// A ghost of a mirrored clamp (DESIGN.md section 3): its displacement is the odd reflection
// u_ghost = -u_mirror of the body particle mirrored across the clamped face, so u = 0 on the
// face to second order. It carries no strain energy of its own and its force goes back to the
// mirror particle (the chain rule), which keeps the system conservative.
struct MirrorGhost {
  Index ghost = 0;
  Index mirror = 0;
};

struct Damping {
  double viscous = 0.0;  // mass-proportional coefficient c [1/s]: f = -c m v
  bool kinetic = false;  // zero the velocities at every peak of the kinetic energy
  bool any() const { return viscous > 0.0 || kinetic; }
};

}  // namespace tlsph
