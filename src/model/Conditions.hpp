// Boundary conditions, loads and damping (chapter section 6.11; docs/method.md section 3).
#pragma once

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "model/FollowingPressure.hpp"
#include "model/Types.hpp"

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
// the particle's area, or a total force already shared out), scaled by the ramp. A following
// pressure's force depends on the present shape: `following` computes it, and `force` holds
// the dead pressure's, its size at the reference configuration (for diagnostics).
template <int D>
struct Load {
  std::string name;
  std::vector<Index> particles;
  std::vector<Vec<D>> force;
  Ramp ramp;
  std::optional<FollowingPressure<D>> following;
};

// A ghost of a mirrored clamp (docs/method.md section 3). Its displacement extrapolates the body's
// across the clamped face so that u equals the face's prescribed displacement u_p there:
//   u_ghost = u_p(X_ghost) + w1 (u_1 - u_p(X_1)) + w2 (u_2 - u_p(X_2)),
// with particle 1 the body particle mirrored across the face and particle 2 the next one inward
// on the same line (w2 = 0, second = -1: the odd reflection u_ghost = -u_mirror for a fixed
// face). The ghost carries no strain energy of its own and its force goes back to particles 1
// and 2 with the weights w1, w2 (the chain rule), which keeps the system conservative.
struct MirrorGhost {
  Index ghost = 0;
  Index mirror = 0;  // particle 1
  double w1 = -1.0;
  Index second = -1;  // particle 2, or -1
  double w2 = 0.0;
  int motion = -1;  // index into Scene::prescriptions of the face's motion; -1: held fixed
};

// Prescribed displacement and velocity of a rule at any reference point X (not only at its
// particles), for faces whose ghosts follow the rule by reflection; a rule's particles start
// from zero displacement here.
template <int D>
Vec<D> prescribedDisplacementAt(const Prescription<D>& rule, const Vec<D>& X, double t) {
  switch (rule.motion) {
    case PrescribedMotion::Fixed:
      return Vec<D>::Zero();
    case PrescribedMotion::Velocity:
      return rule.value * rampedAngle(1.0, rule.ramp, t);  // integral of the ramp
    case PrescribedMotion::Displacement:
      return rule.value * rule.ramp.factor(t);
    case PrescribedMotion::Rotation: {
      const Mat<D> R = rotationMatrix<D>(rule.axis, rampedAngle(rule.rate, rule.ramp, t));
      return Vec<D>(rule.point + R * (X - rule.point) - X);
    }
  }
  return Vec<D>::Zero();
}

// Prescribed velocity of a rule at a point now at x: the one switch over the rules' velocities,
// for the solver's prescribed particles (at their own positions) and the mirrored faces (at
// their points' prescribed positions). Only a rotation's velocity depends on where the point is.
template <int D>
Vec<D> prescribedVelocityAtPosition(const Prescription<D>& rule, const Vec<D>& x, double t) {
  switch (rule.motion) {
    case PrescribedMotion::Fixed:
      return Vec<D>::Zero();
    case PrescribedMotion::Velocity:
      return rule.value * rule.ramp.factor(t);
    case PrescribedMotion::Displacement:
      return rule.value * rule.ramp.rate(t);
    case PrescribedMotion::Rotation: {
      const Vec<D> r = x - rule.point;
      return rotationVelocity<D>(rule.axis, rule.rate * rule.ramp.factor(t), r);
    }
  }
  return Vec<D>::Zero();
}

// At a reference point X that follows the rule from zero displacement (a mirrored face's).
template <int D>
Vec<D> prescribedVelocityAt(const Prescription<D>& rule, const Vec<D>& X, double t) {
  if (rule.motion != PrescribedMotion::Rotation) return prescribedVelocityAtPosition(rule, X, t);
  const Vec<D> x = X + prescribedDisplacementAt(rule, X, t);
  return prescribedVelocityAtPosition(rule, x, t);
}

struct Damping {
  double viscous = 0.0;  // mass-proportional coefficient c [1/s]: f = -c m v
  bool kinetic = false;  // zero the velocities at every peak of the kinetic energy
  bool any() const { return viscous > 0.0 || kinetic; }
};

}  // namespace tlsph
