// Why a run that failed a stability check (Guards.hpp) likely failed, and what to do.
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
#include <cstdint>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "explicit/Diagnostics.hpp"
#include "explicit/Solver.hpp"
#include "scene/SceneSetup.hpp"

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

// Which detector fired.
enum class Trigger { Jacobian, NonFinite, Hourglass, Energy };
// Per particle: what drives it, or its neighbours.
enum : std::uint8_t { kPrescribed = 1, kClamp = 2, kLoad = 4 };

// The last state that passed its check.
template <int D>
struct Snapshot {
  long step = 0;
  double time = 0.0;
  std::vector<Vec<D>> displacement, velocity;
  EnergyBalance energy;
  StateScan scan;
};

// The rules a. to e. above, reading the guard's memory.
template <int D>
class LikelyCause {
 public:
  static constexpr double kCrushedJ = 0.5;     // "strongly compressed" for rule c
  static constexpr double kGrowth = 10.0;      // rule d: speed growth per check interval
  static constexpr double kRough = 0.3;        // rule d: high-frequency share of E_kin
  static constexpr double kStrongDrive = 0.1;  // rule c': strain per wave front or load

  LikelyCause(const SceneSetup<D>& setup, const Solver<D>& solver,
              const std::vector<std::uint8_t>& near, const Snapshot<D>& last, double scale,
              double previousSpeed)
      : setup_(setup),
        solver_(solver),
        near_(near),
        last_(last),
        scale_(scale),
        previousSpeed_(previousSpeed) {}

  // "likely ...: what to do", for the instability `out` that `trigger` found.
  std::string of(Trigger trigger, const Instability& out, const StateScan& s,
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
    const double ruleLimit = solver_.stableStepRule().dt / setup_.solver.cfl * cflMax;
    // The operator's linear limit, where it was estimated, is the sharper prediction.
    const SpectralStep& cap = solver_.spectralStep();
    const double spectralLimit = cap.made ? 2.0 / std::sqrt(cap.lambda) : ruleLimit;
    const double stable = std::min(ruleLimit, spectralLimit);
    const double dt = solver_.timeStep();
    const std::string fix = setup_.solver.timeStep > 0.0
                                ? "lower [time] dt, or drop it for the cfl rule"
                                : "lower [time] cfl";
    if (dt > stable && spectralLimit < ruleLimit)
      return "likely the time step: dt = " + number(dt) + " s is " + number(dt / stable, 3) +
             " times velocity Verlet's limit 2 / omega_max = " + number(stable) +
             " s of the operator's fastest mode (omega_max = " + number(std::sqrt(cap.lambda)) +
             " rad/s at the reference state, largest at particle " + std::to_string(cap.particle) +
             "): " + fix;
    if (dt > stable)
      return "likely the time step: dt = " + number(dt) + " s is " + number(dt / stable, 3) +
             " times the predicted stable step " + number(stable) +
             " s ([time] cfl = " + number(cflMax) + " for the " +
             (quadratic ? "quadratic" : "linear") + " correction): " + fix;

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

 private:
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

  const SceneSetup<D>& setup_;
  const Solver<D>& solver_;
  const std::vector<std::uint8_t>& near_;  // per particle: kPrescribed | kClamp | kLoad
  const Snapshot<D>& last_;
  double scale_;
  double previousSpeed_;  // largest speed at the good check before last_
};

}  // namespace guard_detail

}  // namespace tlsph
