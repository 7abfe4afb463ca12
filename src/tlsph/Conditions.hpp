// Boundary conditions, loads and damping (chapter section 6.11; DESIGN.md section 3).
#pragma once

#include <algorithm>
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
};

// Dirichlet condition on a group of particles (ghost clamps are Fixed groups).
template <int D>
struct Prescription {
  std::string name;
  std::vector<Index> particles;
  PrescribedMotion motion = PrescribedMotion::Fixed;
  Vec<D> value = Vec<D>::Zero();
  Ramp ramp;
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

struct Damping {
  double viscous = 0.0;  // mass-proportional coefficient c [1/s]: f = -c m v
  bool kinetic = false;  // zero the velocities at every peak of the kinetic energy
  bool any() const { return viscous > 0.0 || kinetic; }
};

}  // namespace tlsph
