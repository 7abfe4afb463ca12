// What a run needs to continue bitwise from where it stopped (checkpoint/restart): the
// particles' motion, the clock, the kinetic-damping memory and the energy books. Everything
// else the solver holds (forces, loads, ghost motion) is a function of these.
#pragma once

#include <vector>

#include "model/Types.hpp"

namespace tlsph {

template <int D>
struct SolverState {
  double time = 0.0;
  long steps = 0;
  double previousKinetic = 0.0;
  long kineticResets = 0;
  double hourglassWorkDone = 0.0, externalWork = 0.0, boundaryWork = 0.0, damped = 0.0;
  bool staticBooksStarted = false;
  std::vector<Vec<D>> displacement, velocity;
  // The velocities the last force pass saw (mid-step): kept only when the artificial
  // viscosity reads them.
  std::vector<Vec<D>> forceVelocity;
};

}  // namespace tlsph
