// The energy books of a run (docs/method.md section 2): what the body holds (kinetic, strain,
// hourglass energy) against the work put in by loads and boundaries and the energy taken out by
// damping. Their total stays constant up to the O(dt^2) error of the time discretisation, which
// makes it the run's check on itself.
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <vector>

#include "distributed/Communicator.hpp"
#include "model/Conditions.hpp"
#include "model/Particles.hpp"
#include "model/Types.hpp"

namespace tlsph {

// The books at one moment: `total()` is conserved.
struct EnergyBalance {
  double kinetic = 0.0;
  double strain = 0.0;     // sum_I V_I psi(F_I): body and fixed ghosts (mirrored ghosts carry none)
  double hourglass = 0.0;  // E_hg (energy form) or work done against the (6.80) force

  double externalWork = 0.0;  // work of body forces and loads on free particles
  double boundaryWork = 0.0;  // work of prescribed particles on the rest
  double damped = 0.0;  // energy removed by viscous and kinetic damping and artificial viscosity
  double total() const {
    return kinetic + strain + hourglass - externalWork - boundaryWork + damped;
  }
};

// The work terms of one step (or this rank's part of them), each integrated with the
// trapezoidal rule over the step's moves: half with the forces before a move, half with the
// forces after it.
struct StepWork {
  double hourglass = 0.0;  // done BY the textbook (6.80) hourglass force
  double external = 0.0;   // done by body forces and loads on the free particles
  double boundary = 0.0;   // done by prescribed particles and moving mirrored faces on the rest
  double damping = 0.0;    // taken out by viscous damping and the artificial viscosity

  // The books are diagnostics, so a distributed step adds the ranks' parts in rank order.
  void sumOverRanks(Communicator* comm) {
    if (!comm) return;
    std::array<double, 4> books = {hourglass, external, boundary, damping};
    comm->sum(books.data(), 4);
    hourglass = books[0];
    external = books[1];
    boundary = books[2];
    damping = books[3];
  }
};

// Slots of the work terms in a kick's ordered sums (OrderedSum.hpp).
enum WorkSlot : std::size_t { kHourglassWork = 0, kExternalWork = 1, kDampingWork = 2 };

// Half the work over a free particle's drift du of the forces that are not derived from a
// stored energy, with those forces at one end of the drift. Only these are integrated: strain
// energy and the energy form's E_hg are states, read when the books are drawn up. A null
// force is one the run does not have.
template <int D>
struct DriftWork {
  const Vec<D>* external = nullptr;   // loads and body forces: work put in
  const Vec<D>* hourglass = nullptr;  // textbook hourglass force: its work done
  const Vec<D>* viscous = nullptr;    // artificial viscosity: energy taken out

  template <std::size_t N>
  void addHalf(std::array<double, N>& w, Index i, const Vec<D>& du) const {
    if (external) w[kExternalWork] += 0.5 * external[i].dot(du);
    if (hourglass) w[kHourglassWork] += 0.5 * hourglass[i].dot(du);
    if (viscous) w[kDampingWork] -= 0.5 * viscous[i].dot(du);
  }
};

// The running sums of the work terms since the start of the run (saved by checkpoints).
struct EnergyBooks {
  double hourglassWorkDone = 0.0;  // work done BY the hourglass force
  double externalWork = 0.0;
  double boundaryWork = 0.0;
  double damped = 0.0;

  void add(const StepWork& w) {
    hourglassWorkDone += w.hourglass;
    externalWork += w.external;
    boundaryWork += w.boundary;
    damped += w.damping;
  }

  // The balance with the body's present energies; `hourglassEnergy` is the energy form's E_hg,
  // none for the textbook force, whose energy is minus its work done.
  EnergyBalance balance(double kinetic, double strain,
                        std::optional<double> hourglassEnergy) const {
    EnergyBalance e;
    e.kinetic = kinetic;
    e.strain = strain;
    e.hourglass = hourglassEnergy ? *hourglassEnergy : -hourglassWorkDone;
    e.externalWork = externalWork;
    e.boundaryWork = boundaryWork;
    e.damped = damped;
    return e;
  }
};

// The work books of a static step (a solver that finds equilibrium directly): the loads and
// boundaries move from one equilibrium to the next, so their work is booked with the
// trapezoidal rule between the two states. The first step starts from the unloaded state (no
// loads, no reactions): the loads are applied from zero, so for a linear problem the books
// close exactly (Clapeyron).
template <int D>
struct StaticStepBooks {
  // State at the start of the step.
  std::vector<Vec<D>> start, force, external, drive;
  double time = 0.0;
  bool started = false;   // some static step has been booked (saved by checkpoints)
  bool fromZero = false;  // this step starts from the unloaded state

  void begin(const ParticleSet<D>& p, const std::vector<Vec<D>>& externalForce,
             const std::vector<Vec<D>>& ghostDrive, double t) {
    start = p.displacement;
    force = p.force;
    external = externalForce;
    drive = ghostDrive;
    time = t;
    fromZero = !started;
    if (fromZero) {
      for (auto& f : force)
        f.setZero();
      for (auto& f : external)
        f.setZero();
      started = true;
    }
  }

  // The step did not converge: the books are as if it had not begun.
  void abandon() {
    if (fromZero) started = false;
  }

  // Books the step's work once the free particles have settled: the loads' on the free
  // particles, the prescribed particles' and the moving mirrored faces' on the rest.
  void finish(EnergyBooks& books, const ParticleSet<D>& p, const std::vector<Vec<D>>& externalForce,
              const std::vector<Vec<D>>& ghostDrive, const std::vector<Index>& freeParticles,
              const std::vector<Index>& prescribedParticles,
              const std::vector<MirrorGhost>& ghosts) const {
    double externalWork = 0.0, boundaryWork = 0.0;
    for (Index i : freeParticles)
      if (!externalForce.empty())
        externalWork += 0.5 * (external[i] + externalForce[i]).dot(p.displacement[i] - start[i]);
    for (Index i : prescribedParticles)
      boundaryWork -= 0.5 * (force[i] + p.force[i]).dot(p.displacement[i] - start[i]);
    for (std::size_t k = 0; k < drive.size(); ++k) {
      const Index g = ghosts[k].ghost;
      boundaryWork -= 0.5 * (force[g] + p.force[g]).dot(ghostDrive[k] - drive[k]);
    }
    books.externalWork += externalWork;
    books.boundaryWork += boundaryWork;
  }
};

}  // namespace tlsph
