// Advances a Scene in time with velocity Verlet (kick-drift-kick), applying its boundary
// conditions, loads and damping, and keeping the energy books.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <iterator>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "distributed/Communicator.hpp"
#include "explicit/Diagnostics.hpp"
#include "distributed/DomainPartition.hpp"
#include "model/Errors.hpp"
#include "execution/OrderedSum.hpp"
#include "execution/ParallelFor.hpp"
#include "method/ReferenceConfiguration.hpp"
#include "distributed/ReproducibleSum.hpp"
#include "model/Scene.hpp"
#include "execution/SubnormalsToZero.hpp"
#include "method/TimeStep.hpp"
#include "fast/TlsphForces.hpp"

namespace tlsph {

struct SolverSettings {
  double cfl = kDefaultCfl;
  double timeStep = 0.0;  // > 0 overrides the wave-speed rule
};

// Energy books of a run: `total()` is conserved up to the O(dt^2) time discretisation
// error: kinetic + strain + hourglass - work put in by loads and boundaries + energy
// taken out by damping.
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

// What a run needs to continue bitwise from where it stopped (checkpoint/restart): the
// particles' motion, the clock, the kinetic-damping memory and the energy books. Everything
// else the solver holds (forces, loads, ghost motion) is a function of these.
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

// How the particles of a distributed run are split (Solver::partition()).
struct PartitionSummary {
  int ranks = 1;
  std::string method = "single";  // "metis", "bisection" or "single"
  Index halo = 0;                 // particles read from other ranks, summed over the ranks
  double imbalance = 1.0;         // largest rank's pairs + particles over the mean
};

// Neighbours per particle over the whole body.
struct NeighbourStats {
  Index min = 0, max = 0;
  double mean = 0.0;
};

// The particles the quadratic correction's fit could not serve (ReferenceConfiguration's
// linearFallback), over the whole body: how many, the first, and its neighbour count.
struct FallbackSummary {
  Index count = 0, first = -1, neighbours = 0;
};

// A distributed run's split, made before the pair data is built (the pair data is kept for
// this rank's particles and halo only).
struct DistributionPlan {
  bool active = false;        // more than one rank
  DomainPartition partition;  // every rank's part and particles; this rank's halo
  std::vector<Index> rows;    // this rank's particles and halo, ascending
  PartitionSummary summary;
  NeighbourStats neighbours;  // of the whole body
};

template <int D>
class Solver {
 public:
  // The scene's particle arrays must not be resized while the solver lives. With a
  // communicator of more than one rank the run is distributed (issue 11): the particles are
  // partitioned once, each rank advances its own, and the trajectory is bitwise the serial one.
  // The arrays stay whole on every rank; what observes them calls synchronize() first.
  explicit Solver(Scene<D>& scene, const SolverSettings& settings = {},
                  Communicator* comm = nullptr)
      : scene_(scene),
        plan_(planDistribution(scene, comm)),
        ref_(buildReference(scene, plan_, comm)),
        forces_(ref_, scene.materials, scene.particles.material, scene.particles.volume,
                scene.hourglass(), scene.quadrature, scene.viscosity, 0.5 * scene.supportRadius,
                mirrorGhostList(scene)) {
    if (!(settings.cfl > 0.0)) throw SetupError("the CFL number must be positive");
    const auto& p = scene.particles;
    if (plan_.active) {
      comm_ = comm;
      stable_ = globalStableStep(stableStep(p, scene.materials, settings.cfl,
                                            forces_.hourglassStiffness(),
                                            &plan_.partition.owned[comm->rank()]));
    } else {
      stable_ = stableStep(p, scene.materials, settings.cfl, forces_.hourglassStiffness());
    }
    dt_ = settings.timeStep > 0.0 ? settings.timeStep : stable_.dt;
    std::vector<int> slot(p.size(), -1);
    for (Index i = 0; i < p.size(); ++i) {
      if (p.motion[i] == Motion::Free) {
        free_.push_back(i);
      } else if (p.motion[i] == Motion::Mirrored) {
        continue;
      } else {
        slot[i] = static_cast<int>(prescribed_.size());
        prescribed_.push_back(i);
      }
    }
    rule_.assign(prescribed_.size(), -1);
    start_.resize(prescribed_.size());
    step_.assign(prescribed_.size(), Vec<D>::Zero());
    for (std::size_t r = 0; r < scene.prescriptions.size(); ++r)
      for (Index i : scene.prescriptions[r].particles) {
        if (i < 0 || i >= p.size() || slot[i] < 0)
          throw SetupError("prescription '" + scene.prescriptions[r].name + "' names particle " +
                           std::to_string(i) + ", which is not a prescribed particle");
        rule_[slot[i]] = static_cast<int>(r);
      }
    for (std::size_t k = 0; k < prescribed_.size(); ++k)
      start_[k] = p.displacement[prescribed_[k]];
    hasExternal_ = !scene.gravity.isZero() || !scene.loads.empty();
    if (hasExternal_) {
      external_.assign(p.size(), Vec<D>::Zero());
      computeExternalForces(0.0);
    }
    for (const auto& m : scene.mirrorGhosts)
      if (m.motion >= 0 && scene.prescriptions[m.motion].motion != PrescribedMotion::Fixed)
        movingMirrors_ = true;
    ownFree_ = free_;
    for (std::size_t k = 0; k < prescribed_.size(); ++k)
      ownPrescribed_.push_back(k);
    for (std::size_t k = 0; k < scene.mirrorGhosts.size(); ++k)
      ownGhosts_.push_back(k);
    if (comm_) distribute();
    summariseFallback();
    updateMirrorDrive(0.0);
    mirrorGhostMotion();
    if (forces_.viscosityEnabled()) forceVelocity_ = scene.particles.velocity;
    {
      const SubnormalsToZero subnormals;  // every force of a run in the step's mode
      forces_.compute(scene.particles.displacement, scene.particles.force,
                      &scene.particles.velocity);
    }
    chainMirrorForces();
    previousKinetic_ = kineticEnergy(scene.particles);
  }

  // Distributed: every rank's particles onto every rank (displacements, velocities, forces,
  // F, P, ...), for what observes the whole body (series rows, frames, guards, checkpoints);
  // once per state. Nothing in a serial run.
  void synchronize() {
    if (!comm_ || synchronized_) return;
    auto& p = scene_.particles;
    comm_->gatherAll(p.displacement);
    comm_->gatherAll(p.velocity);
    comm_->gatherAll(p.force);
    comm_->gatherAll(forceVelocity_);
    forces_.gatherAll();
    synchronized_ = true;
  }
  const PartitionSummary& partition() const { return plan_.summary; }
  Communicator* communicator() const { return comm_; }
  // Distributed: this rank's particles (ascending); null in a serial run (all of them).
  const std::vector<Index>* ownedParticles() const {
    return comm_ ? &plan_.partition.owned[comm_->rank()] : nullptr;
  }
  // Neighbours per particle over the whole body.
  NeighbourStats neighbourStats() const {
    if (comm_) return plan_.neighbours;
    const auto& nb = ref_.neighbours;
    const Index n = nb.particleCount();
    NeighbourStats s;
    s.min = n > 0 ? nb.count(0) : 0;
    for (Index i = 0; i < n; ++i) {
      s.min = std::min(s.min, nb.count(i));
      s.max = std::max(s.max, nb.count(i));
    }
    s.mean = n > 0 ? double(nb.pairCount()) / n : 0.0;
    return s;
  }
  const FallbackSummary& linearFallback() const { return fallback_; }
  // The reference neighbours of particle i (a distributed rank keeps lists for its particles
  // and halo only; another particle's is searched for).
  std::vector<Index> neighboursOf(Index i) const {
    const auto& nb = ref_.neighbours;
    if (!comm_ || nb.count(i) > 0)
      return {nb.neighbour.begin() + nb.offset[i], nb.neighbour.begin() + nb.offset[i + 1]};
    const NeighbourList one =
        buildNeighbourRows<D>(scene_.particles.referencePosition, {i},
                              checkedKernel(scene_).supportRadius(), scene_.periodicBox);
    return {one.neighbour.begin() + one.offset[i], one.neighbour.begin() + one.offset[i + 1]};
  }

  double time() const { return time_; }
  double timeStep() const { return dt_; }
  // The wave-speed rule's step at the run's C_cfl and what sets it (also when [time] dt
  // overrides it).
  const StableStep& stableStepRule() const { return stable_; }
  long stepCount() const { return steps_; }
  const ReferenceConfiguration<D>& reference() const { return ref_; }
  const TlsphForces<D>& forces() const { return forces_; }
  // External force (body forces and loads) on each particle at the current time; empty
  // when the scene has none.
  const std::vector<Vec<D>>& externalForce() const { return external_; }

  void step() {
    const SubnormalsToZero subnormals;  // wave precursors: SubnormalsToZero.hpp
    auto& p = scene_.particles;
    const double halfDt = 0.5 * dt_;
    const double c = scene_.damping.viscous;
    // Without viscous damping the second kick's division by 1 + c dt/2 and the damping work
    // are left out: they divide by 1 and add zeros, so every bit stays, and divisions are the
    // kicks' slowest instructions (issue 12). The first kick's c v stays: subtracting -0 could
    // turn a -0 velocity into +0.
    const bool damped = c != 0.0;
    // This rank's particles (all of them in a serial run).
    const Index nFree = static_cast<Index>(ownFree_.size());
    // Work is integrated for the non-conservative terms only: the textbook hourglass force
    // and the artificial viscosity (booked as damping). The energy form's E_hg is a state.
    const bool hourglass = !forces_.hourglassForce().empty();
    const bool viscous = forces_.viscosityEnabled();
    double hourglassWork = 0.0, externalWork = 0.0, boundaryWork = 0.0, dampingWork = 0.0;

    // Kick and drift; each work term is integrated with the trapezoidal rule over the
    // drift: half with the forces before it, half with the forces after it.
    // Sums in a fixed order (OrderedSum.hpp): 0 hourglass, 1 external, 2 damping work.
    const auto kick = orderedSums<3>(nFree, [&](Index k, std::array<double, 3>& w) {
      const Index i = ownFree_[k];
      p.velocity[i] += halfDt * (totalForce(i) / p.mass[i] - c * p.velocity[i]);
      const Vec<D> du = dt_ * p.velocity[i];
      p.displacement[i] += du;
      if (damped) w[2] += c * p.mass[i] * p.velocity[i].dot(du);
      if (hasExternal_) w[1] += 0.5 * external_[i].dot(du);
      if (hourglass) w[0] += 0.5 * forces_.hourglassForce()[i].dot(du);
      if (viscous) w[2] -= 0.5 * forces_.viscousForce()[i].dot(du);
    });
    hourglassWork += kick[0];
    externalWork += kick[1];
    dampingWork += kick[2];
    for (std::size_t k : ownPrescribed_) {
      const Index i = prescribed_[k];
      step_[k] = prescribedMove(k, time_ + dt_) - p.displacement[i];
      p.displacement[i] += step_[k];
      boundaryWork -= 0.5 * p.force[i].dot(step_[k]);
      if (hourglass) hourglassWork += 0.5 * forces_.hourglassForce()[i].dot(step_[k]);
    }

    time_ += dt_;
    // A moving mirrored face does work -f_ghost . (change of the ghost's prescribed part).
    std::vector<Vec<D>> driveStep;
    if (movingMirrors_) {
      driveStep = drive_;
      updateMirrorDrive(time_);
      for (std::size_t k = 0; k < drive_.size(); ++k)
        driveStep[k] = drive_[k] - driveStep[k];
      for (std::size_t k : ownGhosts_)
        boundaryWork -= 0.5 * p.force[scene_.mirrorGhosts[k].ghost].dot(driveStep[k]);
    }
    mirrorGhostMotion();
    // The artificial viscosity sees the mid-step velocities.
    if (viscous) forceVelocity_ = p.velocity;
    exchangeHalo();
    forces_.compute(p.displacement, p.force, &p.velocity);
    chainMirrorForces();
    if (!driveStep.empty())
      for (std::size_t k : ownGhosts_)
        boundaryWork -= 0.5 * p.force[scene_.mirrorGhosts[k].ghost].dot(driveStep[k]);
    if (hasExternal_) computeExternalForces(time_);

    // 0 hourglass, 1 external, 2 damping work, 3 kinetic energy (fixed order: OrderedSum.hpp).
    const auto kick2 = orderedSums<4>(nFree, [&](Index k, std::array<double, 4>& w) {
      const Index i = ownFree_[k];
      const Vec<D> du = dt_ * p.velocity[i];  // still the mid-step velocity
      if (hasExternal_) w[1] += 0.5 * external_[i].dot(du);
      if (hourglass) w[0] += 0.5 * forces_.hourglassForce()[i].dot(du);
      if (viscous) w[2] -= 0.5 * forces_.viscousForce()[i].dot(du);
      // Viscous damping taken implicitly in the second kick: stable for any c.
      const Vec<D> v = p.velocity[i] + halfDt * totalForce(i) / p.mass[i];
      p.velocity[i] = damped ? Vec<D>(v / (1.0 + c * halfDt)) : v;
      w[3] += 0.5 * p.mass[i] * p.velocity[i].squaredNorm();
    });
    hourglassWork += kick2[0];
    externalWork += kick2[1];
    dampingWork += kick2[2];
    double kinetic = kick2[3];
    for (std::size_t k : ownPrescribed_) {
      const Index i = prescribed_[k];
      boundaryWork -= 0.5 * p.force[i].dot(step_[k]);
      if (hourglass) hourglassWork += 0.5 * forces_.hourglassForce()[i].dot(step_[k]);
      p.velocity[i] = prescribedVelocity(k, time_);
    }
    if (comm_) {  // the books are diagnostics: the ranks' parts added in rank order
      std::array<double, 4> books = {hourglassWork, externalWork, boundaryWork, dampingWork};
      comm_->sum(books.data(), 4);
      hourglassWork = books[0];
      externalWork = books[1];
      boundaryWork = books[2];
      dampingWork = books[3];
    }

    if (scene_.damping.kinetic) {
      // The peak test decides the trajectory: its kinetic energy is summed with bits that do
      // not depend on the order, the threads or the ranks (ReproducibleSum.hpp).
      kineticTerms_.resize(ownFree_.size());
      parallelFor(nFree, [&](Index k) {
        kineticTerms_[k] = 0.5 * p.mass[ownFree_[k]] * p.velocity[ownFree_[k]].squaredNorm();
      });
      kinetic = reproducibleSum(kineticTerms_, comm_);
      if (kinetic < previousKinetic_) {  // just past a peak: take the kinetic energy out
        parallelFor(nFree, [&](Index k) { p.velocity[ownFree_[k]].setZero(); });
        dampingWork += kinetic;
        kinetic = 0.0;
        ++kineticResets_;
      }
      previousKinetic_ = kinetic;
    }
    mirrorGhostMotion();

    hourglassWorkDone_ += hourglassWork;
    externalWork_ += externalWork;
    boundaryWork_ += boundaryWork;
    damped_ += dampingWork;
    ++steps_;
    synchronized_ = false;
  }

  EnergyBalance energyBalance() const {
    requireSynchronized();
    EnergyBalance e;
    e.kinetic = kineticEnergy(scene_.particles);
    e.strain = forces_.strainEnergy();
    e.hourglass = forces_.hourglassConservative()
                      ? forces_.hourglassEnergy(scene_.particles.displacement)
                      : -hourglassWorkDone_;
    e.externalWork = externalWork_;
    e.boundaryWork = boundaryWork_;
    e.damped = damped_;
    return e;
  }

  // Out-of-balance force of a quasi-static run: |sum over free particles of (f_int + f_ext)|_2
  // relative to the size of the forces that hold the body (external loads and reactions).
  double residualRatio() const {
    requireSynchronized();
    const auto& p = scene_.particles;
    double residual = 0.0, reference = 0.0;
    for (Index i : free_) {
      residual += totalForce(i).squaredNorm();
      if (hasExternal_) reference += external_[i].squaredNorm();
    }
    for (Index i : prescribed_)
      reference += p.force[i].squaredNorm();
    return reference > 0.0 ? std::sqrt(residual / reference) : std::sqrt(residual);
  }

  long kineticDampingResets() const { return kineticResets_; }

  // The longest load or prescription ramp: a static run cannot have converged before it.
  double rampEnd() const {
    double end = scene_.gravityRamp.duration;
    for (const auto& l : scene_.loads)
      end = std::max(end, l.ramp.duration);
    for (const auto& r : scene_.prescriptions)
      end = std::max(end, r.ramp.duration);
    return end;
  }

  // Force that prescription r (a clamp or a prescribed region) exerts on the rest of the
  // system: minus the internal force on its prescribed particles, and for the mirrored ghosts
  // that follow it, the net force the chain rule leaves on the body, -(1 - w1 - w2) f_ghost
  // (the internal forces of all particles sum to zero). In equilibrium the reactions balance
  // the loads.
  Vec<D> reaction(std::size_t r) const {
    requireSynchronized();
    const auto& p = scene_.particles;
    Vec<D> R = Vec<D>::Zero();
    for (Index i : scene_.prescriptions.at(r).particles)
      R -= p.force[i];
    for (const auto& m : scene_.mirrorGhosts)
      if (m.motion == static_cast<int>(r)) R -= (1.0 - m.w1 - m.w2) * p.force[m.ghost];
    return R;
  }

  // The particles the integrator moves (the unknowns of a static solve).
  const std::vector<Index>& freeParticles() const { return free_; }

  // Internal plus external force on particle i at the last evaluation (for a free particle,
  // with the forces of the mirrored ghosts that follow it): the out-of-balance force.
  Vec<D> netForce(Index i) const { return totalForce(i); }

  // Puts the scene in the static state of load time t, for solvers that find equilibrium
  // directly (NewtonSolver): prescribed particles and moving mirrored faces at their
  // displacements at t, loads and body forces at t, velocities zero, forces recomputed for the
  // free particles' present displacements. Counts as one step; the work of the loads and
  // prescribed particles since the previous state is booked with the trapezoidal rule when
  // finishStaticStep() is called once the free particles have settled. The first static step
  // starts from the unloaded state (no loads, no reactions): the loads are applied from zero,
  // so for a linear problem the books close exactly (Clapeyron).
  void beginStaticStep(double t) {
    const auto& p = scene_.particles;
    staticStart_ = p.displacement;
    staticForce_ = p.force;
    staticExternal_ = external_;
    staticDrive_ = drive_;
    staticTime_ = time_;
    staticFromZero_ = !staticBooksStarted_;
    if (staticFromZero_) {
      for (auto& f : staticForce_)
        f.setZero();
      for (auto& f : staticExternal_)
        f.setZero();
      staticBooksStarted_ = true;
    }
    moveToStaticTime(t);
    ++steps_;
  }

  // Undoes a static step that did not converge: back to the state beginStaticStep() saved.
  void abandonStaticStep() {
    scene_.particles.displacement = staticStart_;
    moveToStaticTime(staticTime_);
    if (staticFromZero_) staticBooksStarted_ = false;
    --steps_;
  }

  void finishStaticStep() {
    const auto& p = scene_.particles;
    double external = 0.0, boundary = 0.0;
    for (Index i : free_)
      if (hasExternal_)
        external +=
            0.5 * (staticExternal_[i] + external_[i]).dot(p.displacement[i] - staticStart_[i]);
    for (Index i : prescribed_)
      boundary -= 0.5 * (staticForce_[i] + p.force[i]).dot(p.displacement[i] - staticStart_[i]);
    for (std::size_t k = 0; k < staticDrive_.size(); ++k) {
      const Index g = scene_.mirrorGhosts[k].ghost;
      boundary -= 0.5 * (staticForce_[g] + p.force[g]).dot(drive_[k] - staticDrive_[k]);
    }
    externalWork_ += external;
    boundaryWork_ += boundary;
  }

  SolverState<D> state() const {
    requireSynchronized();
    SolverState<D> s;
    s.time = time_;
    s.steps = steps_;
    s.previousKinetic = previousKinetic_;
    s.kineticResets = kineticResets_;
    s.hourglassWorkDone = hourglassWorkDone_;
    s.externalWork = externalWork_;
    s.boundaryWork = boundaryWork_;
    s.damped = damped_;
    s.staticBooksStarted = staticBooksStarted_;
    s.displacement = scene_.particles.displacement;
    s.velocity = scene_.particles.velocity;
    s.forceVelocity = forceVelocity_;
    return s;
  }

  // Puts the solver back into a state() of the same scene: the forces are recomputed from the
  // same inputs as when the state was left, so the run continues bit for bit.
  void restore(const SolverState<D>& s) {
    auto& p = scene_.particles;
    const auto n = static_cast<std::size_t>(p.size());
    if (s.displacement.size() != n || s.velocity.size() != n ||
        (forces_.viscosityEnabled() && s.forceVelocity.size() != n))
      throw SetupError("the saved state holds " + std::to_string(s.displacement.size()) +
                       " particles, the scene " + std::to_string(n));
    const SubnormalsToZero subnormals;  // the forces as the step computed them
    time_ = s.time;
    steps_ = s.steps;
    previousKinetic_ = s.previousKinetic;
    kineticResets_ = s.kineticResets;
    hourglassWorkDone_ = s.hourglassWorkDone;
    externalWork_ = s.externalWork;
    boundaryWork_ = s.boundaryWork;
    damped_ = s.damped;
    staticBooksStarted_ = s.staticBooksStarted;
    p.displacement = s.displacement;
    forceVelocity_ = s.forceVelocity;
    p.velocity = forceVelocity_.empty() ? s.velocity : forceVelocity_;
    updateMirrorDrive(time_);
    mirrorGhostMotion();
    exchangeHalo();
    forces_.compute(p.displacement, p.force, &p.velocity);
    chainMirrorForces();
    if (hasExternal_) computeExternalForces(time_);
    p.velocity = s.velocity;
    mirrorGhostMotion();
    synchronized_ = false;
  }

  // Recomputes the forces (and the external forces at the current time) for the particles'
  // present displacements and velocities, without advancing: for a state put back from a
  // copy, e.g. to write the last good frame of a run that went unstable.
  void reevaluate() {
    const SubnormalsToZero subnormals;  // as in step()
    auto& p = scene_.particles;
    mirrorGhostMotion();
    if (forces_.viscosityEnabled()) forceVelocity_ = p.velocity;
    exchangeHalo();
    forces_.compute(p.displacement, p.force, &p.velocity);
    chainMirrorForces();
    if (hasExternal_) computeExternalForces(time_);
    synchronized_ = false;
  }

 private:
  static std::vector<Index> mirrorGhostList(const Scene<D>& scene) {
    const auto& p = scene.particles;
    std::vector<Index> ghosts;
    std::vector<std::uint8_t> listed(p.size(), 0);
    auto freeParticle = [&](Index i) {
      return i >= 0 && i < p.size() && p.motion[i] == Motion::Free;
    };
    for (const auto& m : scene.mirrorGhosts) {
      if (m.ghost < 0 || m.ghost >= p.size() || p.motion[m.ghost] != Motion::Mirrored ||
          !freeParticle(m.mirror) || (m.second >= 0 && !freeParticle(m.second)))
        throw SetupError("mirror ghost " + std::to_string(m.ghost) + " of particle " +
                         std::to_string(m.mirror) +
                         " must be a mirrored particle whose mirror particles are free ones");
      if (m.motion >= static_cast<int>(scene.prescriptions.size()))
        throw SetupError("mirror ghost " + std::to_string(m.ghost) + " names motion rule " +
                         std::to_string(m.motion) + ", which does not exist");
      listed[m.ghost] = 1;
      ghosts.push_back(m.ghost);
    }
    for (Index i = 0; i < p.size(); ++i)
      if (p.motion[i] == Motion::Mirrored && !listed[i])
        throw SetupError("particle " + std::to_string(i) + " is mirrored but has no mirror");
    return ghosts;
  }

  // The prescribed part of each mirrored ghost's displacement at time t and its rate,
  //   d_g = u_p(X_g) - w1 u_p(X_1) - w2 u_p(X_2)   (MirrorGhost),
  // into drive_ and driveRate_; kept only when some mirrored face moves (else d_g = 0).
  void updateMirrorDrive(double t) {
    if (!movingMirrors_) return;
    const auto& X = scene_.particles.referencePosition;
    const auto n = scene_.mirrorGhosts.size();
    drive_.assign(n, Vec<D>::Zero());
    driveRate_.assign(n, Vec<D>::Zero());
    for (std::size_t k = 0; k < n; ++k) {
      const auto& m = scene_.mirrorGhosts[k];
      if (m.motion < 0) continue;
      const auto& rule = scene_.prescriptions[m.motion];
      auto part = [&](Vec<D> (*at)(const Prescription<D>&, const Vec<D>&, double)) {
        Vec<D> d = at(rule, X[m.ghost], t) - m.w1 * at(rule, X[m.mirror], t);
        if (m.second >= 0) d -= m.w2 * at(rule, X[m.second], t);
        return d;
      };
      drive_[k] = part(prescribedDisplacementAt<D>);
      driveRate_[k] = part(prescribedVelocityAt<D>);
    }
  }

  // u_ghost = d_g + w1 u_1 + w2 u_2, the same for v: the ghosts extrapolate the body across
  // the face (MirrorGhost).
  void mirrorGhostMotion() {
    auto& p = scene_.particles;
    for (std::size_t k = 0; k < scene_.mirrorGhosts.size(); ++k) {
      const auto& m = scene_.mirrorGhosts[k];
      p.displacement[m.ghost] = m.w1 * p.displacement[m.mirror];
      p.velocity[m.ghost] = m.w1 * p.velocity[m.mirror];
      if (m.second >= 0) {
        p.displacement[m.ghost] += m.w2 * p.displacement[m.second];
        p.velocity[m.ghost] += m.w2 * p.velocity[m.second];
      }
      if (movingMirrors_) {
        p.displacement[m.ghost] += drive_[k];
        p.velocity[m.ghost] += driveRate_[k];
      }
    }
  }

  // The chain rule of the ghost's extrapolation: -dE/du_1 gains w1 (-dE/du_ghost), -dE/du_2
  // gains w2 (-dE/du_ghost). The ghost keeps its own force, from which reaction() is computed.
  // Serial: two faces' ghosts can share a mirror particle.
  void chainMirrorForces() {
    auto& p = scene_.particles;
    for (std::size_t k : ownGhosts_) {  // a ghost and what it follows are on one rank
      const auto& m = scene_.mirrorGhosts[k];
      p.force[m.mirror] += m.w1 * p.force[m.ghost];
      if (m.second >= 0) p.force[m.second] += m.w2 * p.force[m.ghost];
    }
  }

  // Splits the particles among the ranks (on rank 0, from the whole neighbour graph, which
  // only it builds; broadcast), mirrored ghosts with the particles they follow; this rank's
  // halo from its particles' lists; the communication plan. Empty for a serial run.
  static DistributionPlan planDistribution(const Scene<D>& scene, Communicator* comm) {
    DistributionPlan plan;
    if (!comm || comm->size() <= 1) return plan;
    plan.active = true;
    const auto& X = scene.particles.referencePosition;
    const Index n = scene.particles.size();
    const double H = checkedKernel(scene).supportRadius();
    const int rank = comm->rank(), size = comm->size();
    auto& partition = plan.partition;
    std::string method;
    std::vector<double> numbers(5, 0.0);  // halo, imbalance, neighbours min, mean, max
    if (rank == 0) {
      const NeighbourList nb = buildNeighbourList<D>(X, H, scene.periodicBox);
      partition = partitionParticles<D>(X, nb, size);
      std::vector<std::pair<Index, Index>> links;
      for (const auto& m : scene.mirrorGhosts) {
        links.emplace_back(m.ghost, m.mirror);
        if (m.second >= 0) links.emplace_back(m.ghost, m.second);
      }
      keepTogether(partition, links, nb);
      method = partition.method;
      Index least = n > 0 ? nb.count(0) : 0, most = 0;
      for (Index i = 0; i < n; ++i) {
        least = std::min(least, nb.count(i));
        most = std::max(most, nb.count(i));
      }
      numbers = {double(partition.haloTotal()), partition.imbalance(nb), double(least),
                 n > 0 ? double(nb.pairCount()) / n : 0.0, double(most)};
    } else {
      partition.part.assign(static_cast<std::size_t>(n), 0);
    }
    comm->broadcast(partition.part);
    comm->broadcast(method);
    comm->broadcast(numbers);
    partition.parts = size;
    partition.method = method;
    partition.owned.assign(size, {});
    partition.halo.assign(size, {});
    for (Index i = 0; i < n; ++i)
      partition.owned[partition.part[i]].push_back(i);
    const auto& own = partition.owned[rank];
    const NeighbourList mine = buildNeighbourRows<D>(X, own, H, scene.periodicBox);
    auto& halo = partition.halo[rank];
    for (Index i : own)
      for (Index k = mine.offset[i]; k < mine.offset[i + 1]; ++k)
        if (partition.part[mine.neighbour[k]] != rank) halo.push_back(mine.neighbour[k]);
    std::sort(halo.begin(), halo.end());
    halo.erase(std::unique(halo.begin(), halo.end()), halo.end());
    comm->setPartition(partition, mine);
    std::merge(own.begin(), own.end(), halo.begin(), halo.end(), std::back_inserter(plan.rows));
    plan.summary = {size, method, static_cast<Index>(numbers[0]), numbers[1]};
    plan.neighbours = {static_cast<Index>(numbers[2]), static_cast<Index>(numbers[4]), numbers[3]};
    return plan;
  }

  // The pair data: of every particle, or (distributed) of this rank's particles and halo. A
  // set-up error on one rank (a singular correction tensor in its rows) is every rank's: they
  // all build the whole configuration then, which throws the serial run's message.
  static ReferenceConfiguration<D> buildReference(const Scene<D>& scene,
                                                  const DistributionPlan& plan,
                                                  Communicator* comm) {
    auto build = [&](const std::vector<Index>* rows) {
      return buildReferenceConfiguration<D>(
          scene.particles.referencePosition, scene.particles.volume, checkedKernel(scene),
          scene.periodicBox, scene.gradientCorrection, kDefaultMinCorrectionCondition, rows);
    };
    if (!plan.active) return build(nullptr);
    ReferenceConfiguration<D> ref;
    bool failed = false;
    try {
      ref = build(&plan.rows);
    } catch (const SetupError&) {
      failed = true;
    }
    if (comm->any(failed)) build(nullptr);
    return ref;
  }

  // The smallest of the ranks' steps: the lowest index among equal ratios, as serially; the
  // limiting particle's numbers from its rank.
  StableStep globalStableStep(const StableStep& mine) const {
    auto ratioOf = [](const StableStep& s) {
      return s.particle < 0 ? std::numeric_limits<double>::infinity()
                            : s.dx / std::sqrt(s.waveSpeed * s.waveSpeed +
                                               s.hourglassSpeed * s.hourglassSpeed);
    };
    double best = -ratioOf(mine);
    comm_->max(&best, 1);
    double index = ratioOf(mine) == -best ? -double(mine.particle) : -1e300;
    comm_->max(&index, 1);
    const bool limiting = mine.particle == Index(-index);
    const double none = -std::numeric_limits<double>::infinity();
    std::array<double, 4> fields = {limiting ? mine.dt : none, limiting ? mine.dx : none,
                                    limiting ? mine.waveSpeed : none,
                                    limiting ? mine.hourglassSpeed : none};
    comm_->max(fields.data(), 4);
    return {fields[0], Index(-index), fields[1], fields[2], fields[3]};
  }

  // Keeps this rank's share of each particle list.
  void distribute() {
    const auto& owned = plan_.partition.owned[comm_->rank()];
    std::vector<std::uint8_t> mine(static_cast<std::size_t>(scene_.particles.size()), 0);
    for (Index i : owned)
      mine[i] = 1;
    std::erase_if(ownFree_, [&](Index i) { return !mine[i]; });
    std::erase_if(ownPrescribed_, [&](std::size_t k) { return !mine[prescribed_[k]]; });
    std::erase_if(ownGhosts_, [&](std::size_t k) { return !mine[scene_.mirrorGhosts[k].ghost]; });
    forces_.distribute(owned, comm_);
  }

  // The quadratic correction's fall-backs over the whole body (each rank knows its own
  // particles').
  void summariseFallback() {
    const auto& list = ref_.linearFallback;
    if (!comm_) {
      if (!list.empty())
        fallback_ = {Index(list.size()), list.front(), ref_.neighbours.count(list.front())};
      return;
    }
    std::vector<std::uint8_t> mine(static_cast<std::size_t>(scene_.particles.size()), 0);
    for (Index i : *ownedParticles())
      mine[i] = 1;
    double count = 0.0, first = -1e300;
    for (Index i : list)
      if (mine[i]) {
        ++count;
        first = std::max(first, -double(i));
      }
    comm_->sum(&count, 1);
    comm_->max(&first, 1);
    if (count == 0) return;
    const Index i = Index(-first);
    double neighbours = mine[i] ? ref_.neighbours.count(i) : 0.0;
    comm_->max(&neighbours, 1);
    fallback_ = {Index(count), i, Index(neighbours)};
  }

  // Distributed: the halo's displacements (and, for the artificial viscosity, velocities)
  // from their owners, before a force pass.
  void exchangeHalo() {
    if (!comm_) return;
    comm_->exchangeHalo(scene_.particles.displacement);
    if (forces_.viscosityEnabled()) comm_->exchangeHalo(scene_.particles.velocity);
  }

  void requireSynchronized() const {
    if (comm_ && !synchronized_)
      throw std::logic_error("Solver: observed a distributed run without synchronize()");
  }

  static Kernel<D> checkedKernel(const Scene<D>& scene) {
    if (scene.materials.empty()) throw SetupError("the scene has no material");
    if (scene.particles.size() == 0) throw SetupError("the scene has no particles");
    return Kernel<D>(scene.kernel, scene.supportRadius);
  }

  Vec<D> totalForce(Index i) const {
    return hasExternal_ ? Vec<D>(scene_.particles.force[i] + external_[i])
                        : scene_.particles.force[i];
  }

  void computeExternalForces(double t) {
    auto& p = scene_.particles;
    const Vec<D> g = scene_.gravity * scene_.gravityRamp.factor(t);
    // by the threads that read it in the kicks (ParallelFor.hpp)
    parallelFor(p.size(), [&](Index i) { external_[i] = p.mass[i] * g; });
    for (const auto& load : scene_.loads) {
      const double f = load.ramp.factor(t);
      for (std::size_t k = 0; k < load.particles.size(); ++k)
        external_[load.particles[k]] += f * load.force[k];
    }
  }

  // Displacement of prescribed particle k (index into prescribed_) at time t.
  Vec<D> prescribedMove(std::size_t k, double t) const {
    const Index i = prescribed_[k];
    const auto& p = scene_.particles;
    if (rule_[k] < 0) return p.displacement[i] + dt_ * p.velocity[i];  // keeps its velocity
    const auto& rule = scene_.prescriptions[rule_[k]];
    switch (rule.motion) {
      case PrescribedMotion::Fixed:
        return start_[k];
      case PrescribedMotion::Velocity:
        return p.displacement[i] + dt_ * rule.value * rule.ramp.factor(t - 0.5 * dt_);
      case PrescribedMotion::Displacement:
        return start_[k] + rule.value * rule.ramp.factor(t);
      case PrescribedMotion::Rotation: {
        // Exact at every step: x = point + R(theta(t)) (x_start - point), u = x - X.
        const Vec<D>& X = p.referencePosition[i];
        const Mat<D> R = rotationMatrix<D>(rule.axis, rampedAngle(rule.rate, rule.ramp, t));
        return Vec<D>(rule.point + R * (X + start_[k] - rule.point) - X);
      }
    }
    return p.displacement[i];
  }

  void moveToStaticTime(double t) {
    auto& p = scene_.particles;
    time_ = t;
    for (std::size_t k = 0; k < prescribed_.size(); ++k)
      p.displacement[prescribed_[k]] = staticPrescribedDisplacement(k, t);
    for (auto& v : p.velocity)
      v.setZero();
    if (movingMirrors_) {
      updateMirrorDrive(t);
      for (auto& r : driveRate_)
        r.setZero();
    }
    reevaluate();
  }

  // Displacement of prescribed particle k at load time t of a static solve (exact for every
  // rule: a velocity rule's displacement is its integral from 0).
  Vec<D> staticPrescribedDisplacement(std::size_t k, double t) const {
    const Index i = prescribed_[k];
    const auto& p = scene_.particles;
    if (rule_[k] < 0) return start_[k];
    const auto& rule = scene_.prescriptions[rule_[k]];
    if (rule.motion == PrescribedMotion::Rotation) {
      const Vec<D>& X = p.referencePosition[i];
      const Mat<D> R = rotationMatrix<D>(rule.axis, rampedAngle(rule.rate, rule.ramp, t));
      return Vec<D>(rule.point + R * (X + start_[k] - rule.point) - X);
    }
    return Vec<D>(start_[k] + prescribedDisplacementAt(rule, p.referencePosition[i], t));
  }

  Vec<D> prescribedVelocity(std::size_t k, double t) const {
    const auto& p = scene_.particles;
    if (rule_[k] < 0) return p.velocity[prescribed_[k]];
    const auto& rule = scene_.prescriptions[rule_[k]];
    switch (rule.motion) {
      case PrescribedMotion::Fixed:
        return Vec<D>::Zero();
      case PrescribedMotion::Velocity:
        return rule.value * rule.ramp.factor(t);
      case PrescribedMotion::Displacement:
        return rule.value * rule.ramp.rate(t);
      case PrescribedMotion::Rotation: {
        const Index i = prescribed_[k];
        const Vec<D> r = p.referencePosition[i] + p.displacement[i] - rule.point;
        return rotationVelocity<D>(rule.axis, rule.rate * rule.ramp.factor(t), r);
      }
    }
    return Vec<D>::Zero();
  }

  Scene<D>& scene_;
  DistributionPlan plan_;
  ReferenceConfiguration<D> ref_;
  TlsphForces<D> forces_;
  std::vector<Index> free_, prescribed_;
  // What this rank advances: its free particles, slots of prescribed_ and mirrored ghosts
  // (all of them in a serial run).
  std::vector<Index> ownFree_;
  std::vector<std::size_t> ownPrescribed_, ownGhosts_;
  Communicator* comm_ = nullptr;
  bool synchronized_ = false;
  FallbackSummary fallback_;
  std::vector<double> kineticTerms_;
  std::vector<int> rule_;      // per prescribed particle: index into scene.prescriptions, or -1
  std::vector<Vec<D>> start_;  // per prescribed particle: displacement at the start
  std::vector<Vec<D>> step_;   // per prescribed particle: its displacement over this step
  std::vector<Vec<D>> external_;
  bool hasExternal_ = false;
  bool movingMirrors_ = false;             // some mirrored face follows a moving prescription
  std::vector<Vec<D>> drive_, driveRate_;  // per mirrored ghost: prescribed part of u and v
  StableStep stable_;
  double dt_ = 0.0;
  double time_ = 0.0;
  long steps_ = 0;
  double previousKinetic_ = 0.0;
  long kineticResets_ = 0;
  double hourglassWorkDone_ = 0.0;  // work done BY the hourglass force
  double externalWork_ = 0.0;
  double boundaryWork_ = 0.0;
  double damped_ = 0.0;
  std::vector<Vec<D>> forceVelocity_;  // see SolverState::forceVelocity
  // State at the start of a static step (beginStaticStep), for its work books.
  std::vector<Vec<D>> staticStart_, staticForce_, staticExternal_, staticDrive_;
  double staticTime_ = 0.0;
  bool staticBooksStarted_ = false, staticFromZero_ = false;
};

}  // namespace tlsph
