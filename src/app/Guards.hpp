// The stability guards of `tlsph run`: what is checked every [static] check_every steps, and
// what a failed check reports (its likely cause: Instability.hpp).
//
// Detectors, in this order (the first that fires is reported):
//   1. J = det F <= [guard] min_jacobian (default 0) at a body particle (ghosts are skipped):
//      inverted or collapsed material. Checked before finiteness because an inverted
//      neo-Hookean particle has a NaN stress: the inversion is the news, the NaN its echo.
//   2. A non-finite displacement, velocity or force (the lowest-index such particle).
//   3. Hourglass energy below -[guard] energy_error x scale: the hourglass term feeds energy in.
//   4. |E - E_0| > [guard] energy_error x scale (default 0.05; 0 switches 3 and 4 off), E the
//      total of the energy books (EnergyBalance::total(), constant up to O(dt^2) for damped
//      and driven runs too), scale the largest value seen so far of kinetic + |strain| +
//      |hourglass| + |external work| + |boundary work| + damped (at least 1e-30 J, so a run
//      at rest never trips).
// A passing check keeps a copy of the displacements and velocities: the last good state.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "app/Frames.hpp"
#include "app/Instability.hpp"
#include "explicit/Diagnostics.hpp"
#include "explicit/Solver.hpp"
#include "output/VtuFile.hpp"
#include "scene/SceneSetup.hpp"

namespace tlsph {

// What a guard remembers across checks, for checkpoint/restart (the last good state is the
// state the run restarts from).
struct GuardState {
  EnergyBalance initial;
  double total0 = 0.0;
  double scale = 0.0;
  double previousSpeed = 0.0;
};

template <int D>
class RunGuard {
 public:
  static constexpr double kScaleFloor = 1e-30;  // J: the energy scale of a run at rest

  // Takes the present state (before the first step) as the first good one.
  RunGuard(SceneSetup<D>& setup, Solver<D>& solver) : setup_(setup), solver_(solver) {
    solver.synchronize();
    const auto& p = setup.scene.particles;
    initial_ = solver.energyBalance();
    total0_ = initial_.total();
    scale_ = std::max(kScaleFloor, guard_detail::bookMagnitude(initial_));
    near_.assign(p.size(), 0);
    for (Index i = 0; i < p.size(); ++i)
      if (p.motion[i] != Motion::Free)  // prescribed, or a clamp's ghost (fixed or mirrored)
        near_[i] |= (i < Index(setup.ghost.size()) && setup.ghost[i]) ? guard_detail::kClamp
                                                                      : guard_detail::kPrescribed;
    for (const auto& load : setup.scene.loads)
      for (Index i : load.particles)
        near_[i] |= guard_detail::kLoad;
    save(scanState<D>(p, solver.forces().deformationGradient(), setup.ghost), initial_);
  }

  GuardState state() const { return {initial_, total0_, scale_, previousSpeed_}; }

  // Continues a guard's memory in a restarted run: the present state (the checkpoint's, which
  // passed its check) becomes the last good one.
  void resume(const GuardState& g) {
    initial_ = g.initial;
    total0_ = g.total0;
    scale_ = g.scale;
    save(scanState<D>(setup_.scene.particles, solver_.forces().deformationGradient(), setup_.ghost),
         solver_.energyBalance());
    previousSpeed_ = g.previousSpeed;
  }

  // At a check: nothing if the state is healthy (it becomes the last good one), else the
  // instability found, with its likely cause.
  std::optional<Instability> check() {
    using namespace guard_detail;
    solver_.synchronize();
    const auto& p = setup_.scene.particles;
    const auto& F = solver_.forces().deformationGradient();
    const StateScan s = scanState<D>(p, F, setup_.ghost);
    const EnergyBalance e = solver_.energyBalance();
    const bool finiteBooks = booksFinite(e);
    if (finiteBooks) scale_ = std::max(scale_, bookMagnitude(e));
    const double bound = setup_.guard.energyError;

    Instability out;
    out.step = solver_.stepCount();
    out.time = solver_.time();
    out.lastGoodStep = last_.step;
    out.lastGoodTime = last_.time;
    Trigger trigger;
    if (s.smallestJParticle >= 0 && s.smallestJ <= setup_.guard.minJacobian) {
      trigger = Trigger::Jacobian;
      out.quantity = "J";
      out.value = s.smallestJ;
      out.particle = s.smallestJParticle;
      out.description =
          "J = det F = " + number(s.smallestJ) + " <= " + number(setup_.guard.minJacobian) +
          (setup_.guard.minJacobian == 0.0 ? " (inverted material)"
                                           : " ([guard] min_jacobian: collapsed material)");
    } else if (s.nonFinite >= 0) {
      trigger = Trigger::NonFinite;
      out.quantity = s.nonFiniteQuantity;
      out.particle = s.nonFinite;
      const Vec<D>& v = out.quantity == "displacement" ? p.displacement[s.nonFinite]
                        : out.quantity == "velocity"   ? p.velocity[s.nonFinite]
                                                       : p.force[s.nonFinite];
      for (int a = 0; a < D; ++a)
        if (!std::isfinite(v[a])) {
          out.value = v[a];
          break;
        }
      out.description = "non-finite " + out.quantity + " (" + number(out.value) + ")";
    } else if (!finiteBooks) {
      trigger = Trigger::NonFinite;
      out.quantity = "energy_books";
      out.value = e.total();
      out.description = "non-finite energy books (E = " + number(e.total()) + ")";
    } else if (bound > 0.0 && e.hourglass < -bound * scale_) {
      trigger = Trigger::Hourglass;
      out.quantity = "hourglass_energy";
      out.value = e.hourglass;
      out.particle = largestHourglassForce(s);
      out.description = "hourglass energy " + number(e.hourglass) + " J, below zero by " +
                        number(-e.hourglass / scale_, 3) + " of the energy scale " +
                        number(scale_) + " J (bound " + number(bound) + "); largest " +
                        (solver_.forces().hourglassForce().empty() ? "speed" : "hourglass force");
    } else if (bound > 0.0 && std::abs(e.total() - total0_) > bound * scale_) {
      trigger = Trigger::Energy;
      out.quantity = "energy_balance_error";
      out.value = e.total() - total0_;
      out.particle = s.fastest;
      out.description = "energy balance error E - E0 = " + number(out.value) + " J, " +
                        number(std::abs(out.value) / scale_, 3) + " of the energy scale " +
                        number(scale_) + " J (bound " + number(bound) + "; " +
                        largestChange(last_.energy, e) + "); fastest";
    } else {
      save(s, e);
      return std::nullopt;
    }
    if (out.particle >= 0) {
      out.referencePosition = components<D>(p.referencePosition[out.particle]);
      out.currentPosition = components<D>(p.currentPosition(out.particle));
    }
    out.cause = guard_detail::LikelyCause<D>(setup_, solver_, near_, last_, scale_, previousSpeed_)
                    .of(trigger, out, s, e);
    return out;
  }

  // Writes NAME_failed.vtu (the present state) and NAME_last_good.vtu (the last good state,
  // put back into the particles with the forces re-evaluated: the solver is left there) into
  // the output directory, with every output field, whatever [output] fields says.
  // Distributed: every rank re-evaluates, rank 0 writes.
  void writeFrames(Instability& found) {
    namespace fs = std::filesystem;
    const fs::path dir = setup_.output.directory;
    const Communicator* comm = solver_.communicator();
    const bool root = !comm || comm->rank() == 0;
    found.failedFrame = dir / (setup_.name + "_failed.vtu");
    found.lastGoodFrame = dir / (setup_.name + "_last_good.vtu");
    solver_.synchronize();
    std::vector<double> error = hourglassErrorField(setup_, solver_, allFrameFields());
    if (root) {
      fs::create_directories(dir);
      writeVtuFile(makeFrame(setup_, solver_, allFrameFields(), &error), found.failedFrame);
    }
    auto& p = setup_.scene.particles;
    p.displacement = last_.displacement;
    p.velocity = last_.velocity;
    solver_.reevaluate();
    solver_.synchronize();
    error = hourglassErrorField(setup_, solver_, allFrameFields());
    if (!root) return;
    Frame good = makeFrame(setup_, solver_, allFrameFields(), &error);
    good.time = last_.time;
    good.step = last_.step;
    writeVtuFile(good, found.lastGoodFrame);
  }

 private:
  using Trigger = guard_detail::Trigger;
  using Snapshot = guard_detail::Snapshot<D>;

  void save(const StateScan& s, const EnergyBalance& e) {
    const auto& p = setup_.scene.particles;
    previousSpeed_ = last_.scan.largestSpeed;
    last_.step = solver_.stepCount();
    last_.time = solver_.time();
    last_.displacement = p.displacement;
    last_.velocity = p.velocity;
    last_.energy = e;
    last_.scan = s;
  }

  // The book entry that changed most since the last good check, with its change.
  static std::string largestChange(const EnergyBalance& before, const EnergyBalance& after) {
    const std::pair<const char*, double> changes[] = {
        {"kinetic", after.kinetic - before.kinetic},
        {"strain", after.strain - before.strain},
        {"hourglass", after.hourglass - before.hourglass},
        {"external work", after.externalWork - before.externalWork},
        {"boundary work", after.boundaryWork - before.boundaryWork},
        {"damped", after.damped - before.damped}};
    const auto* most = &changes[0];
    for (const auto& c : changes)
      if (std::abs(c.second) > std::abs(most->second)) most = &c;
    return std::string(most->first) + " changed most since the last check, by " +
           (most->second >= 0 ? "+" : "") + guard_detail::number(most->second) + " J";
  }

  Index largestHourglassForce(const StateScan& s) const {
    const auto& f = solver_.forces().hourglassForce();
    if (f.empty()) return s.fastest;
    Index best = -1;
    double largest = -1.0;
    for (Index i = 0; i < Index(f.size()); ++i)
      if (f[i].norm() > largest) {
        largest = f[i].norm();
        best = i;
      }
    return best;
  }

  SceneSetup<D>& setup_;
  Solver<D>& solver_;
  EnergyBalance initial_;
  double total0_ = 0.0;
  double scale_ = kScaleFloor;
  std::vector<std::uint8_t> near_;  // per particle: kPrescribed | kClamp | kLoad
  Snapshot last_;
  double previousSpeed_ = 0.0;  // largest speed at the good check before last_
};

}  // namespace tlsph
