// The stability guards of `tlsph run`: what is checked every [static] check_every steps, and
// the diagnosis when a check fails.
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
//
// The cause is a guess from what the books and the two states show; the rules, first match:
//   a. the hourglass energy is negative (detector 3, or below a quarter of its bound at the
//      failing check or, if that is not finite, at the last good one): the (6.80) force is
//      not conservative and is feeding energy in -> [hourglass] form = energy or smaller alpha;
//   b. dt is above the predicted stable step, the solver's time-step rule (TimeStep.hpp:
//      wave speed and hourglass stiffness) at C_max = 0.5 for the quadratic correction and
//      0.8 for the linear one (the measured stability limits, TimeStep.hpp and README
//      "Gradient correction") -> lower [time] cfl / dt;
//   c. the material inverted (detector 1, or the run went non-finite after the last good
//      check showed J < 0.5 somewhere) next to prescribed, clamped or loaded particles, under
//      gravity, or after a gradual squeeze (J < 0.5 already at the last good check) -> loads
//      or prescribed motion too large for the mesh / material parameters;
//   c'. (inversion or non-finite only) a prescribed speed above 0.1 of the wave speed, or a
//      load stress above 0.1 E: each wave front or the load alone strains the material by
//      more than 10 % -> loads or prescribed motion too large;
//   d. the largest speed grew more than tenfold over one check interval and the velocity
//      field is rough at the particle scale (the part of the kinetic energy in v_I minus its
//      kernel average over the neighbours exceeds 30 %): a high-frequency blow-up -> the time
//      step is too large for this set-up: lower [time] cfl;
//   e. otherwise a fallback per detector that says what is known and what to try.
// "likely" in every message: these are heuristics, the frames written next to the run show
// what really happened.
#pragma once

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "app/Frames.hpp"
#include "output/VtuFile.hpp"
#include "scene/SceneSetup.hpp"
#include "explicit/Diagnostics.hpp"
#include "explicit/Solver.hpp"

namespace tlsph {

// Why and where a run was stopped as unstable.
struct Instability {
  long step = 0;
  double time = 0.0;
  // What tripped: "J", "displacement" / "velocity" / "force" (non-finite), "energy_books"
  // (non-finite), "hourglass_energy" or "energy_balance_error".
  std::string quantity;
  double value = 0.0;       // J, the non-finite value, the energy [J], or the error [J]
  std::string description;  // the quantity and its value in words, for the message
  Index particle = -1;      // -1: none in particular
  std::vector<double> referencePosition, currentPosition;
  std::string cause;  // "likely ...: what to do"
  long lastGoodStep = 0;
  double lastGoodTime = 0.0;
  std::filesystem::path lastGoodFrame, failedFrame;
};

namespace guard_detail {

inline std::string number(double v, int digits = 4) {
  std::ostringstream s;
  s.precision(digits);
  s << v;
  return s.str();
}

template <int D>
std::vector<double> components(const Vec<D>& v) {
  return std::vector<double>(v.data(), v.data() + D);
}

inline std::string vectorText(const std::vector<double>& v) {
  std::string out;
  for (double x : v) {
    if (!out.empty()) out += ' ';
    out += number(x, 6);
  }
  return out;
}

// kinetic + |strain| + |hourglass| + |external work| + |boundary work| + damped
inline double bookMagnitude(const EnergyBalance& e) {
  return std::abs(e.kinetic) + std::abs(e.strain) + std::abs(e.hourglass) +
         std::abs(e.externalWork) + std::abs(e.boundaryWork) + std::abs(e.damped);
}

inline bool booksFinite(const EnergyBalance& e) {
  return std::isfinite(bookMagnitude(e));
}

}  // namespace guard_detail

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
  static constexpr double kCrushedJ = 0.5;      // "strongly compressed" for rule c
  static constexpr double kGrowth = 10.0;       // rule d: speed growth per check interval
  static constexpr double kRough = 0.3;         // rule d: high-frequency share of E_kin
  static constexpr double kStrongDrive = 0.1;   // rule c': strain per wave front or load

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
        near_[i] |= (i < Index(setup.ghost.size()) && setup.ghost[i]) ? kClamp : kPrescribed;
    for (const auto& load : setup.scene.loads)
      for (Index i : load.particles)
        near_[i] |= kLoad;
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
    out.cause = likelyCause(trigger, out, s, e);
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
  enum class Trigger { Jacobian, NonFinite, Hourglass, Energy };
  enum : std::uint8_t { kPrescribed = 1, kClamp = 2, kLoad = 4 };

  struct Snapshot {
    long step = 0;
    double time = 0.0;
    std::vector<Vec<D>> displacement, velocity;
    EnergyBalance energy;
    StateScan scan;
  };

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

  // Share of the kinetic energy of the free particles in v_I - <v>_I, <v>_I the kernel-weighted
  // mean velocity of I's neighbours: near 0 for smooth fields, near 1 or more for a particle-
  // scale (checkerboard) pattern.
  // Distributed: a collective (each rank sums its own particles, whose lists it keeps).
  double roughness(const std::vector<Vec<D>>& v) const {
    const auto& p = setup_.scene.particles;
    const auto& ref = solver_.reference();
    const auto& nb = ref.neighbours;
    const auto* owned = solver_.ownedParticles();
    const Index count = owned ? static_cast<Index>(owned->size()) : p.size();
    std::vector<double> roughParts, allParts;
    for (Index q = 0; q < count; ++q) {
      const Index i = owned ? (*owned)[q] : q;
      if (p.motion[i] != Motion::Free || !v[i].allFinite()) continue;
      Vec<D> mean = Vec<D>::Zero();
      double weight = 0.0;
      for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k) {
        mean += ref.kernelValue[k] * v[nb.neighbour[k]];
        weight += ref.kernelValue[k];
      }
      if (weight > 0.0) mean /= weight;
      roughParts.push_back(p.mass[i] * (v[i] - mean).squaredNorm());
      allParts.push_back(p.mass[i] * v[i].squaredNorm());
    }
    const double rough = reproducibleSum(roughParts, solver_.communicator()),
                 all = reproducibleSum(allParts, solver_.communicator());
    return all > 0.0 && std::isfinite(rough) ? rough / all : 0.0;
  }

  // The strongest drive, if it strains the material by more than kStrongDrive: a prescribed
  // speed v imposes a strain of about v / c at each wave front (c the material's wave
  // speed), a load a strain of about its stress / E. Empty: none that strong.
  std::string strongDrive() const {
    using guard_detail::number;
    const auto& p = setup_.scene.particles;
    double worst = 0.0;
    std::string what;
    for (Index i = 0; i < p.size(); ++i) {
      if (p.motion[i] != Motion::Prescribed || (near_[i] & kClamp)) continue;
      const Vec<D>& v = p.velocity[i].allFinite() ? p.velocity[i] : last_.velocity[i];
      const double c = waveSpeed(setup_.scene.materials[p.material[i]]);
      if (v.norm() / c > worst) {
        worst = v.norm() / c;
        what = "prescribed speed " + number(v.norm()) + " m/s at particle " + std::to_string(i) +
               " is " + number(worst, 3) + " of the wave speed " + number(c) + " m/s";
      }
    }
    for (const auto& load : setup_.scene.loads)
      for (std::size_t k = 0; k < load.particles.size(); ++k) {
        const Index i = load.particles[k];
        const double area = std::pow(p.volume[i], double(D - 1) / D);
        const double E = elasticConstants(setup_.scene.materials[p.material[i]]).youngsModulus;
        const double stress = load.force[k].norm() / area;
        if (stress / E > worst) {
          worst = stress / E;
          what = "load '" + load.name + "' is about " + number(stress) + " Pa at particle " +
                 std::to_string(i) + ", " + number(worst, 3) + " of E = " + number(E) + " Pa";
        }
      }
    return worst > kStrongDrive ? what : std::string();
  }

  bool isNeighbourOrSelf(Index i, Index j) const {
    if (i == j) return true;
    if (i < 0 || j < 0) return false;
    for (Index k : solver_.neighboursOf(i))
      if (k == j) return true;
    return false;
  }

  // What is next to particle i (itself or a reference neighbour), as words; empty: nothing.
  std::string surroundings(Index i) const {
    if (i < 0) return {};
    std::uint8_t flags = near_[i];
    for (Index j : solver_.neighboursOf(i))
      flags |= near_[j];
    std::string what;
    auto add = [&](const char* w) {
      if (!what.empty()) what += ", ";
      what += w;
    };
    if (flags & kPrescribed) add("prescribed motion");
    if (flags & kClamp) add("a clamp");
    if (flags & kLoad) add("a load");
    if (!setup_.scene.gravity.isZero()) add("gravity");
    return what;
  }

  std::string likelyCause(Trigger trigger, const Instability& out, const StateScan& s,
                          const EnergyBalance& e) const {
    using guard_detail::number;
    const auto& p = setup_.scene.particles;
    const bool finiteBooks = guard_detail::booksFinite(e);
    const bool finiteState = s.nonFinite < 0;
    const double bound = setup_.guard.energyError > 0.0 ? setup_.guard.energyError : 0.05;

    // a. The hourglass term feeding energy in.
    const double hourglass = finiteBooks ? e.hourglass : last_.energy.hourglass;
    if (trigger == Trigger::Hourglass || hourglass < -0.25 * bound * scale_)
      return "likely the hourglass term feeding energy in (hourglass energy " + number(hourglass) +
             " J < 0" + (finiteBooks ? "" : " at the last good check") +
             "; the Ganzenmueller force (6.80) is not conservative): use [hourglass] form = "
             "energy or a smaller alpha";

    // b. A time step above the predicted stable step.
    const bool quadratic = setup_.scene.gradientCorrection == GradientCorrection::Quadratic;
    const double cflMax = quadratic ? 0.5 : 0.8;
    const double stable = solver_.stableStepRule().dt / setup_.solver.cfl * cflMax;
    const double dt = solver_.timeStep();
    if (dt > stable)
      return "likely the time step: dt = " + number(dt) + " s is " + number(dt / stable, 3) +
             " times the predicted stable step " + number(stable) +
             " s ([time] cfl = " + number(cflMax) + " for the " +
             (quadratic ? "quadratic" : "linear") + " correction): " +
             (setup_.solver.timeStep > 0.0 ? "lower [time] dt, or drop it for the cfl rule"
                                           : "lower [time] cfl");

    // c. Inverted material next to what drives the body, or squeezed gradually (for an
    // inversion: the smallest J of the last good check was already small, there or next to it).
    const Index squeezed = trigger == Trigger::Jacobian ? out.particle
                           : trigger == Trigger::NonFinite && last_.scan.smallestJ < kCrushedJ
                               ? last_.scan.smallestJParticle
                               : Index(-1);
    const bool crushedBefore = squeezed >= 0 && last_.scan.smallestJ < kCrushedJ &&
                               isNeighbourOrSelf(squeezed, last_.scan.smallestJParticle);
    if (squeezed >= 0) {
      const std::string around = surroundings(squeezed);
      if (!around.empty() || crushedBefore) {
        std::string where = trigger == Trigger::Jacobian
                                ? std::string("the particle")
                                : "at the last good check (step " + std::to_string(last_.step) +
                                      ") J was " + number(last_.scan.smallestJ) + " at particle " +
                                      std::to_string(squeezed) + " (X = " +
                                      guard_detail::vectorText(guard_detail::components<D>(
                                          p.referencePosition[squeezed])) +
                                      "), which";
        where += around.empty() ? " was squeezed gradually, J = " + number(last_.scan.smallestJ) +
                                      " at the last good check"
                                : " is next to " + around;
        return "likely loads or prescribed motion too large for the mesh / material "
               "parameters: " +
               where + "; reduce them or ramp them more slowly, or refine dx";
      }
    }

    // c'. A drive that strains the material by more than kStrongDrive per wave front or load.
    if (trigger == Trigger::Jacobian || trigger == Trigger::NonFinite) {
      const std::string drive = strongDrive();
      if (!drive.empty())
        return "likely loads or prescribed motion too large for the mesh / material "
               "parameters: " +
               drive + "; reduce them or ramp them more slowly, or refine dx";
    }

    // d. Velocities growing fast at the particle scale.
    const double speedNow = finiteState ? s.largestSpeed : last_.scan.largestSpeed;
    const double speedBefore = finiteState ? last_.scan.largestSpeed : previousSpeed_;
    const double growth = speedNow / std::max(speedBefore, 1e-300);
    const double rough = roughness(finiteState ? p.velocity : last_.velocity);
    if (growth > kGrowth && rough > kRough)
      return "likely the time step: the largest speed grew " + number(growth, 3) +
             " times over the last check interval, at the particle scale (" +
             number(100.0 * rough, 3) + " % of the kinetic energy): lower [time] cfl";

    // e. Fallbacks.
    switch (trigger) {
      case Trigger::Jacobian:
        return "likely a local instability (the particle is away from loads and prescribed "
               "particles): lower [time] cfl, or raise [hourglass] alpha if the frames show "
               "hourglass modes";
      case Trigger::Energy:
        return "likely the time step or the hourglass term: lower [time] cfl, or use "
               "[hourglass] form = energy";
      default: {
        const double alpha = setup_.scene.hourglassCoefficient;
        return "likely the time step: the state went from healthy (step " +
               std::to_string(last_.step) + ") to non-finite within " +
               std::to_string(out.step - last_.step) +
               " steps, as an explicit step beyond its stability limit does: lower [time] cfl" +
               (alpha > 10.0 ? " ([hourglass] alpha = " + number(alpha) +
                                   " stiffens the particle scale and lowers that limit)"
                             : std::string()) +
               "; [static] check_every catches it earlier";
      }
    }
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
