// Advances a Scene in time with velocity Verlet (kick-drift-kick): from the displacements to
// the forces to the next velocities, applying the scene's boundary conditions, loads and
// damping, and keeping the energy books (EnergyBooks.hpp). The prescribed particles
// (PrescribedMotion.hpp), the mirrored clamps' ghosts (MirroredGhosts.hpp) and a distributed
// run's split (distributed/DistributionPlan.hpp) each have their own file.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "distributed/Communicator.hpp"
#include "distributed/DistributionPlan.hpp"
#include "distributed/ReproducibleSum.hpp"
#include "execution/OrderedSum.hpp"
#include "execution/SubnormalsToZero.hpp"
#include "explicit/Diagnostics.hpp"
#include "explicit/EnergyBooks.hpp"
#include "explicit/ExternalForces.hpp"
#include "explicit/MirroredGhosts.hpp"
#include "explicit/PrescribedMotion.hpp"
#include "explicit/SolverState.hpp"
#include "fast/TlsphForces.hpp"
#include "method/ReferenceConfiguration.hpp"
#include "method/TimeStep.hpp"
#include "model/Errors.hpp"
#include "model/RigidModes.hpp"
#include "model/Scene.hpp"

namespace tlsph {

struct SolverSettings {
  double cfl = kDefaultCfl;
  double timeStep = 0.0;  // > 0 overrides the wave-speed rule
  // Cap the rule's step at the operator's own limit (method/TimeStep.hpp spectralStepLimit);
  // off only to measure the rule alone (the stability map).
  bool spectralLimit = true;
};

template <int D>
class Solver {
 public:
  // The scene's particle arrays must not be resized while the solver lives. With a
  // communicator of more than one rank the run is distributed: the particles are partitioned
  // once, each rank advances its own, and the trajectory is bitwise the serial one. The
  // arrays stay whole on every rank; what observes them calls synchronize() first.
  explicit Solver(Scene<D>& scene, const SolverSettings& settings = {},
                  Communicator* comm = nullptr)
      : scene_(scene),
        plan_(planDistribution(scene, comm, checkedKernel(scene).supportRadius())),
        ref_(buildPairData(scene, checkedKernel(scene), plan_, comm)),
        forces_(ref_, scene.materials, scene.particles.material, scene.particles.volume,
                scene.hourglass(), scene.quadrature, scene.viscosity, 0.5 * scene.supportRadius,
                MirroredGhosts<D>::checkedGhostList(scene), scene.particles.quadratureMoments()) {
    if (!(settings.cfl > 0.0)) throw SetupError("the CFL number must be positive");
    const auto& p = scene.particles;
    const std::vector<double> spacing = neighbourhoodSpacing<D>(ref_.neighbours, p.volume);
    if (plan_.active) {
      comm_ = comm;
      stable_ = globalStableStep(
          stableStep(p, scene.materials, settings.cfl, forces_.hourglassStiffness(),
                     &plan_.partition.owned[comm->rank()], spacing),
          *comm);
    } else {
      stable_ = stableStep(p, scene.materials, settings.cfl, forces_.hourglassStiffness(), nullptr,
                           spacing);
    }
    dt_ = settings.timeStep > 0.0 ? settings.timeStep : stable_.dt;
    stepGiven_ = settings.timeStep > 0.0;
    for (Index i = 0; i < p.size(); ++i)
      if (p.motion[i] == Motion::Free) free_.push_back(i);
    prescribed_ = PrescribedParticles<D>(scene);
    prescribedStep_.assign(prescribed_.size(), Vec<D>::Zero());
    loads_ = ExternalForces<D>(scene);
    ghosts_ = MirroredGhosts<D>(scene);
    ownFree_ = free_;
    if (comm_) distribute();
    fallback_ = summariseFallback(ref_, comm_ ? &owned_ : nullptr, comm_);
    ghosts_.move(scene.particles);
    if (forces_.viscosityEnabled()) forceVelocity_ = scene.particles.velocity;
    {
      const SubnormalsToZero subnormals;  // every force of a run in the step's mode
      forces_.compute(scene.particles.displacement, scene.particles.force,
                      &scene.particles.velocity);
    }
    ghosts_.chainForces(scene.particles.force);
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
    return comm_ ? plan_.neighbours : neighbourStatsOf(ref_.neighbours);
  }
  const FallbackSummary& linearFallback() const { return fallback_; }
  const IntegrationConstraintSummary& integrationConstraint() const {
    return ref_.integrationConstraint;
  }
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
  // Before the first step: the step becomes min(rule, spectralStepLimit) unless [time] dt was
  // given.
  void limitTimeStep(const SpectralEstimate& estimate) {
    spectral_ = SpectralStep{estimate};
    if (estimate.made) spectral_.limit = spectralStepLimit(estimate.lambda);
    spectral_.binds = !stepGiven_ && estimate.made && spectral_.limit < dt_;
    if (spectral_.binds) dt_ = spectral_.limit;
  }
  // The cap and whether it binds; made = false when none was estimated.
  const SpectralStep& spectralStep() const { return spectral_; }
  // The wave-speed rule's step at the run's C_cfl and what sets it (also when [time] dt
  // overrides it).
  const StableStep& stableStepRule() const { return stable_; }
  long stepCount() const { return steps_; }
  const ReferenceConfiguration<D>& reference() const { return ref_; }
  const TlsphForces<D>& forces() const { return forces_; }
  // External force (body forces and loads) on each particle at the current time; empty
  // when the scene has none.
  const std::vector<Vec<D>>& externalForce() const { return loads_.force(); }

  // One step of velocity Verlet: kick and drift with the forces of the present displacements,
  // the boundaries moved to the new time, the forces of the new displacements, the second kick.
  void step() {
    const SubnormalsToZero subnormals;  // wave precursors: SubnormalsToZero.hpp
    auto& p = scene_.particles;
    const double halfDt = 0.5 * dt_;
    const double c = scene_.damping.viscous;
    // Without viscous damping the second kick's division by 1 + c dt/2 and the damping work
    // are left out: they divide by 1 and add zeros, so every bit stays, and divisions are the
    // kicks' slowest instructions. The first kick's c v stays: subtracting -0 could turn a -0
    // velocity into +0.
    const bool damped = c != 0.0;
    // This rank's particles (all of them in a serial run).
    const Index nFree = static_cast<Index>(ownFree_.size());
    StepWork work;

    // Kick and drift, with this step's work over the drift (EnergyBooks.hpp), summed in a
    // fixed order (OrderedSum.hpp).
    const DriftWork<D> before = driftWork();
    const auto kick = orderedSums<3>(nFree, [&](Index k, std::array<double, 3>& w) {
      const Index i = ownFree_[k];
      p.velocity[i] += halfDt * (totalForce(i) / p.mass[i] - c * p.velocity[i]);
      const Vec<D> du = dt_ * p.velocity[i];
      p.displacement[i] += du;
      if (damped) w[kDampingWork] += c * p.mass[i] * p.velocity[i].dot(du);
      before.addHalf(w, i, du);
    });
    work.hourglass += kick[kHourglassWork];
    work.external += kick[kExternalWork];
    work.damping += kick[kDampingWork];
    for (std::size_t k : prescribed_.own()) {
      const Index i = prescribed_.particle(k);
      prescribedStep_[k] =
          prescribed_.displacementAtStepEnd(k, time_ + dt_, dt_) - p.displacement[i];
      p.displacement[i] += prescribedStep_[k];
      bookPrescribedHalf(work, i, prescribedStep_[k]);
    }

    time_ += dt_;
    const std::vector<Vec<D>> driveStep = ghosts_.advanceDrive(time_);
    ghosts_.bookDriveWork(p.force, driveStep, work.boundary);
    ghosts_.move(p);
    // The artificial viscosity sees the mid-step velocities.
    if (forces_.viscosityEnabled()) forceVelocity_ = p.velocity;
    exchangeHalo();
    forces_.compute(p.displacement, p.force, &p.velocity);
    ghosts_.chainForces(p.force);
    ghosts_.bookDriveWork(p.force, driveStep, work.boundary);
    if (loads_.any()) loads_.update(time_);

    // The second kick, with the other half of the drift's work; the kinetic energy in slot 3.
    const DriftWork<D> after = driftWork();
    const auto kick2 = orderedSums<4>(nFree, [&](Index k, std::array<double, 4>& w) {
      const Index i = ownFree_[k];
      const Vec<D> du = dt_ * p.velocity[i];  // still the mid-step velocity
      after.addHalf(w, i, du);
      // Viscous damping taken implicitly in the second kick: stable for any c.
      const Vec<D> v = p.velocity[i] + halfDt * totalForce(i) / p.mass[i];
      p.velocity[i] = damped ? Vec<D>(v / (1.0 + c * halfDt)) : v;
      w[3] += 0.5 * p.mass[i] * p.velocity[i].squaredNorm();
    });
    work.hourglass += kick2[kHourglassWork];
    work.external += kick2[kExternalWork];
    work.damping += kick2[kDampingWork];
    double kinetic = kick2[3];
    for (std::size_t k : prescribed_.own()) {
      const Index i = prescribed_.particle(k);
      bookPrescribedHalf(work, i, prescribedStep_[k]);
      p.velocity[i] = prescribed_.velocity(k, time_);
    }
    work.sumOverRanks(comm_);

    if (scene_.damping.kinetic) {
      // The peak test decides the trajectory: its kinetic energy is summed with bits that do
      // not depend on the order, the threads or the ranks (ReproducibleSum.hpp).
      kineticTerms_.resize(ownFree_.size());
      for (Index k = 0; k < nFree; ++k)
        kineticTerms_[k] = 0.5 * p.mass[ownFree_[k]] * p.velocity[ownFree_[k]].squaredNorm();
      kinetic = reproducibleSum(kineticTerms_, comm_);
      if (kinetic < previousKinetic_) {  // just past a peak: take the kinetic energy out
        for (Index k = 0; k < nFree; ++k)
          p.velocity[ownFree_[k]].setZero();
        work.damping += kinetic;
        kinetic = 0.0;
        ++kineticResets_;
      }
      previousKinetic_ = kinetic;
    }
    ghosts_.move(p);

    books_.add(work);
    ++steps_;
    synchronized_ = false;
  }

  EnergyBalance energyBalance() const {
    requireSynchronized();
    std::optional<double> hourglassEnergy;
    if (forces_.hourglassConservative())
      hourglassEnergy = forces_.hourglassEnergy(scene_.particles.displacement);
    return books_.balance(kineticEnergy(scene_.particles), forces_.strainEnergy(), hourglassEnergy);
  }

  // Out-of-balance force of a quasi-static run: |sum over free particles of (f_int + f_ext)|_2
  // relative to the size of the forces that hold the body (external loads and reactions).
  // For a free body (leaveOutRigidPart) the sum is of the forces' deformation part.
  double residualRatio() const {
    requireSynchronized();
    const auto& p = scene_.particles;
    double residual = 0.0, reference = 0.0;
    for (Index i : free_) {
      if (!rigidLeftOut_) residual += totalForce(i).squaredNorm();
      if (loads_.any()) reference += loads_.force()[i].squaredNorm();
    }
    if (rigidLeftOut_) {
      Eigen::VectorXd r(D * static_cast<Index>(free_.size()));
      for (std::size_t k = 0; k < free_.size(); ++k)
        r.template segment<D>(D * k) = totalForce(free_[k]);
      RigidModes<D> rigid;
      rigid.update(free_, p.referencePosition, p.displacement);
      rigid.project(r);
      residual = r.squaredNorm();
    }
    for (Index i : prescribed_.particles())
      reference += p.force[i].squaredNorm();
    return reference > 0.0 ? std::sqrt(residual / reference) : std::sqrt(residual);
  }

  // A static solve of a body nothing holds (the Newton solver's): its loads' rigid part, what
  // is left of their balance, is no deformation's to remove, and residualRatio leaves it out.
  void leaveOutRigidPart() { rigidLeftOut_ = true; }

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
  // system: minus the internal force on its prescribed particles, and the ghosts' part
  // (MirroredGhosts::addReaction; the internal forces of all particles sum to zero). In
  // equilibrium the reactions balance the loads.
  Vec<D> reaction(std::size_t r) const {
    requireSynchronized();
    const auto& p = scene_.particles;
    Vec<D> R = Vec<D>::Zero();
    for (Index i : scene_.prescriptions.at(r).particles)
      R -= p.force[i];
    ghosts_.addReaction(r, p.force, R);
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
  // free particles' present displacements. Counts as one step; its work is booked by
  // finishStaticStep() once the free particles have settled (StaticStepBooks).
  void beginStaticStep(double t) {
    staticStep_.begin(scene_.particles, loads_.force(), ghosts_.drive(), time_);
    moveToStaticTime(t);
    ++steps_;
  }

  // Undoes a static step that did not converge: back to the state beginStaticStep() saved.
  void abandonStaticStep() {
    scene_.particles.displacement = staticStep_.start;
    moveToStaticTime(staticStep_.time);
    staticStep_.abandon();
    --steps_;
  }

  void finishStaticStep() {
    staticStep_.finish(books_, scene_.particles, loads_.force(), ghosts_.drive(), free_,
                       prescribed_.particles(), scene_.mirrorGhosts);
  }

  SolverState<D> state() const {
    requireSynchronized();
    SolverState<D> s;
    s.time = time_;
    s.steps = steps_;
    s.previousKinetic = previousKinetic_;
    s.kineticResets = kineticResets_;
    s.hourglassWorkDone = books_.hourglassWorkDone;
    s.externalWork = books_.externalWork;
    s.boundaryWork = books_.boundaryWork;
    s.damped = books_.damped;
    s.staticBooksStarted = staticStep_.started;
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
    books_.hourglassWorkDone = s.hourglassWorkDone;
    books_.externalWork = s.externalWork;
    books_.boundaryWork = s.boundaryWork;
    books_.damped = s.damped;
    staticStep_.started = s.staticBooksStarted;
    p.displacement = s.displacement;
    forceVelocity_ = s.forceVelocity;
    p.velocity = forceVelocity_.empty() ? s.velocity : forceVelocity_;
    ghosts_.updateDrive(time_);
    ghosts_.move(p);
    exchangeHalo();
    forces_.compute(p.displacement, p.force, &p.velocity);
    ghosts_.chainForces(p.force);
    if (loads_.any()) loads_.update(time_);
    p.velocity = s.velocity;
    ghosts_.move(p);
    synchronized_ = false;
  }

  // Recomputes the forces (and the external forces at the current time) for the particles'
  // present displacements and velocities, without advancing: for a state put back from a
  // copy, e.g. to write the last good frame of a run that went unstable.
  void reevaluate() {
    const SubnormalsToZero subnormals;  // as in step()
    auto& p = scene_.particles;
    ghosts_.move(p);
    if (forces_.viscosityEnabled()) forceVelocity_ = p.velocity;
    exchangeHalo();
    forces_.compute(p.displacement, p.force, &p.velocity);
    ghosts_.chainForces(p.force);
    if (loads_.any()) loads_.update(time_);
    synchronized_ = false;
  }

 private:
  static Kernel<D> checkedKernel(const Scene<D>& scene) {
    if (scene.materials.empty()) throw SetupError("the scene has no material");
    if (scene.particles.size() == 0) throw SetupError("the scene has no particles");
    return Kernel<D>(scene.kernel, scene.supportRadius);
  }

  // Keeps this rank's share of each particle list.
  void distribute() {
    owned_ = plan_.ownedMask(comm_->rank(), scene_.particles.size());
    std::erase_if(ownFree_, [&](Index i) { return !owned_[i]; });
    prescribed_.keepOwn(owned_);
    ghosts_.keepOwn(owned_);
    forces_.distribute(plan_.partition.owned[comm_->rank()], comm_);
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

  // The forces whose work over a drift is integrated (DriftWork), as they are now.
  DriftWork<D> driftWork() const {
    DriftWork<D> w;
    if (loads_.any()) w.external = loads_.force().data();
    if (!forces_.hourglassForce().empty()) w.hourglass = forces_.hourglassForce().data();
    if (forces_.viscosityEnabled()) w.viscous = forces_.viscousForce().data();
    return w;
  }

  // Half the work over a prescribed particle's move du, with the forces at one end of it:
  // the prescribed particle does -f . du on the rest, and the textbook hourglass force on it
  // does its own work.
  void bookPrescribedHalf(StepWork& work, Index i, const Vec<D>& du) const {
    work.boundary -= 0.5 * scene_.particles.force[i].dot(du);
    if (!forces_.hourglassForce().empty())
      work.hourglass += 0.5 * forces_.hourglassForce()[i].dot(du);
  }

  Vec<D> totalForce(Index i) const {
    return loads_.any() ? Vec<D>(scene_.particles.force[i] + loads_.force()[i])
                        : scene_.particles.force[i];
  }

  // The static state of load time t: prescribed particles and faces where their rules put
  // them, everything at rest, the forces of that state.
  void moveToStaticTime(double t) {
    auto& p = scene_.particles;
    time_ = t;
    for (std::size_t k = 0; k < prescribed_.size(); ++k)
      p.displacement[prescribed_.particle(k)] = prescribed_.staticDisplacement(k, t);
    for (auto& v : p.velocity)
      v.setZero();
    ghosts_.holdDriveAt(t);
    reevaluate();
  }

  Scene<D>& scene_;
  DistributionPlan plan_;
  ReferenceConfiguration<D> ref_;
  TlsphForces<D> forces_;
  std::vector<Index> free_;
  PrescribedParticles<D> prescribed_;
  MirroredGhosts<D> ghosts_;
  // What this rank advances: its free particles (all of them in a serial run); its particles
  // as a mask (distributed runs only).
  std::vector<Index> ownFree_;
  std::vector<std::uint8_t> owned_;
  Communicator* comm_ = nullptr;
  bool synchronized_ = false;
  FallbackSummary fallback_;
  std::vector<double> kineticTerms_;
  std::vector<Vec<D>> prescribedStep_;  // per prescribed particle: its move over this step
  bool rigidLeftOut_ = false;           // residualRatio of a free body
  ExternalForces<D> loads_;
  StableStep stable_;
  double dt_ = 0.0;
  bool stepGiven_ = false;
  SpectralStep spectral_;
  double time_ = 0.0;
  long steps_ = 0;
  double previousKinetic_ = 0.0;
  long kineticResets_ = 0;
  EnergyBooks books_;
  std::vector<Vec<D>> forceVelocity_;  // see SolverState::forceVelocity
  StaticStepBooks<D> staticStep_;
};

}  // namespace tlsph
