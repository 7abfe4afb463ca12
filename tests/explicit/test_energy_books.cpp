// The energy books (EnergyBooks.hpp): an undamped free vibration keeps them balanced and the
// linear momentum exact; each term has the sign the balance gives it (work put in by loads and
// boundaries, energy taken out by damping); a static step books the trapezoidal work.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <utility>

#include "TestSupport.hpp"
#include "explicit/EnergyBooks.hpp"
#include "explicit/Solver.hpp"
#include "scene/Config.hpp"
#include "scene/SceneBuilder.hpp"

using namespace tlsph;
using namespace tlsph::testing;
namespace fs = std::filesystem;

namespace {

struct Drift {
  double energy = 0.0;    // max |E_total(t) - E_total(0)| / E_total(0)
  double momentum = 0.0;  // max |sum m v| / sum m |v|
  double strainPeak = 0.0;
};

// A free block set swinging with a smooth, zero-mean velocity field, run for `steps` steps of
// the default CFL number; a smaller `cfl` covers the same simulated time in more steps.
template <int D>
Drift freeVibration(const std::string& material, double alpha, int steps, double cfl = kDefaultCfl,
                    GradientCorrection correction = GradientCorrection::Linear) {
  const double dx = 0.01;
  std::array<int, D> counts;
  counts.fill(D == 2 ? 10 : 5);
  counts[0] *= 2;
  std::mt19937 rng(41);
  auto scene =
      sceneOf<D>(perturbedBlock<D>(counts, dx, 0.1, rng), dx, 2.5, testMaterial(material), alpha);
  scene.gradientCorrection = correction;
  const double c = waveSpeed(scene.materials[0]);
  const double length = counts[0] * dx;
  auto& p = scene.particles;
  for (Index i = 0; i < p.size(); ++i) {
    // Bending-like transverse velocity, 2% of the wave speed, plus a little noise that
    // excites the short-wavelength modes the hourglass term acts on.
    const double xi = p.referencePosition[i].x() / length;
    p.velocity[i][1] = 0.02 * c * std::cos(std::numbers::pi * xi);
    p.velocity[i] += randomVector<D>(rng, 1e-3 * c);
  }
  Vec<D> mean = Vec<D>::Zero();
  double mass = 0.0;
  for (Index i = 0; i < p.size(); ++i) {
    mean += p.mass[i] * p.velocity[i];
    mass += p.mass[i];
  }
  for (auto& v : p.velocity)
    v -= mean / mass;

  SolverSettings settings;
  settings.cfl = cfl;
  Solver<D> solver(scene, settings);
  const double e0 = solver.energyBalance().total();
  const int total = static_cast<int>(std::lround(steps * kDefaultCfl / cfl));
  const int every = total / 60;
  Drift drift;
  for (int s = 1; s <= total; ++s) {
    solver.step();
    if (s % every == 0 || s == total) {
      const EnergyBalance e = solver.energyBalance();
      drift.energy = std::max(drift.energy, std::abs(e.total() - e0) / e0);
      drift.strainPeak = std::max(drift.strainPeak, e.strain / e0);
      double scale = 0.0;
      for (Index i = 0; i < p.size(); ++i)
        scale += p.mass[i] * p.velocity[i].norm();
      drift.momentum = std::max(drift.momentum, linearMomentum(p).norm() / scale);
    }
  }
  return drift;
}

}  // namespace

// Velocity Verlet keeps a shadow energy: the balance oscillates by O(dt^2) instead of drifting.
// The tests check the size at the default CFL number and the second order on halving dt.
TEST(EnergyBooks, FreeVibration2D) {
  const Drift d = freeVibration<2>("neo-hookean", 1.0, 3000);
  const Drift half = freeVibration<2>("neo-hookean", 1.0, 3000, 0.5 * kDefaultCfl);
  std::cout << "2D neo-Hookean, alpha 1, 3000 steps: energy error " << d.energy << " ("
            << half.energy << " at dt/2), momentum " << d.momentum << ", peak strain energy share "
            << d.strainPeak << "\n";
  EXPECT_GT(d.strainPeak, 0.1);  // the energy really changes form
  EXPECT_LT(d.energy, 1e-3);
  EXPECT_LT(half.energy, d.energy / 3.0);
  EXPECT_LT(d.momentum, 1e-12);
}

TEST(EnergyBooks, FreeVibration3D) {
  const Drift d = freeVibration<3>("saint-venant-kirchhoff", 2.0, 2000);
  const Drift half = freeVibration<3>("saint-venant-kirchhoff", 2.0, 2000, 0.5 * kDefaultCfl);
  std::cout << "3D Saint Venant-Kirchhoff, alpha 2, 2000 steps: energy error " << d.energy << " ("
            << half.energy << " at dt/2), momentum " << d.momentum << ", peak strain energy share "
            << d.strainPeak << "\n";
  EXPECT_GT(d.strainPeak, 0.1);
  EXPECT_LT(d.energy, 1e-3);
  EXPECT_LT(half.energy, d.energy / 3.0);
  EXPECT_LT(d.momentum, 1e-12);
}

TEST(EnergyBooks, WithoutHourglassTheBooksStillBalance) {
  const Drift d = freeVibration<2>("linear-elastic", 0.0, 3000);
  EXPECT_LT(d.energy, 1e-3);
  EXPECT_LT(d.momentum, 1e-12);
}

// The defaults (quadratic correction, energy-form penalty alpha = 10 on the same F): the same
// books, with E_hg a state function in them.
TEST(EnergyBooks, FreeVibrationQuadraticCorrection) {
  const auto q = GradientCorrection::Quadratic;
  const Drift d2 = freeVibration<2>("neo-hookean", 10.0, 3000, kDefaultCfl, q);
  const Drift half2 = freeVibration<2>("neo-hookean", 10.0, 3000, 0.5 * kDefaultCfl, q);
  const Drift d3 = freeVibration<3>("saint-venant-kirchhoff", 10.0, 2000, kDefaultCfl, q);
  std::cout << "quadratic correction, alpha 10: 2D energy error " << d2.energy << " ("
            << half2.energy << " at dt/2), 3D " << d3.energy << "\n";
  EXPECT_GT(d2.strainPeak, 0.1);
  EXPECT_LT(d2.energy, 1e-3);
  EXPECT_LT(half2.energy, d2.energy / 3.0);
  EXPECT_LT(d3.energy, 1e-3);
  EXPECT_LT(d2.momentum, 1e-12);
  EXPECT_LT(d3.momentum, 1e-12);
}

// How the books add up: the body's energies and the energy damping took out count positive,
// the work put in by loads and boundaries negative; the textbook hourglass force's energy is
// minus the work it has done, the energy form's is its own state.
TEST(EnergyBooks, TotalCountsWorkPutInAgainstWhatTheBodyHoldsAndDampingTookOut) {
  EnergyBooks books;
  StepWork w;
  w.hourglass = 1.0;
  w.external = 2.0;
  w.boundary = 3.0;
  w.damping = 4.0;
  books.add(w);
  books.add(w);
  const EnergyBalance e = books.balance(10.0, 20.0, std::nullopt);
  EXPECT_EQ(e.hourglass, -2.0);
  EXPECT_EQ(e.externalWork, 4.0);
  EXPECT_EQ(e.boundaryWork, 6.0);
  EXPECT_EQ(e.damped, 8.0);
  EXPECT_EQ(e.total(), 10.0 + 20.0 - 2.0 - 4.0 - 6.0 + 8.0);
  EXPECT_EQ(books.balance(10.0, 20.0, 5.0).hourglass, 5.0);
}

// A drift books half of each non-conservative force's work with the force at one end: the
// loads' as work put in, the artificial viscosity's as energy taken out; a force the run does
// not have books nothing.
TEST(EnergyBooks, DriftWorkBooksHalfOfEachForcesWork) {
  const std::vector<Vec<2>> external = {{1.0, 2.0}, {3.0, -1.0}};
  const std::vector<Vec<2>> hourglass = {{0.5, 0.0}, {-2.0, 4.0}};
  const std::vector<Vec<2>> viscous = {{0.0, 1.0}, {-1.0, -3.0}};
  const Vec<2> du(0.25, 0.5);
  std::array<double, 3> w = {0.0, 0.0, 0.0};
  const DriftWork<2> all{external.data(), hourglass.data(), viscous.data()};
  all.addHalf(w, 1, du);
  EXPECT_EQ(w[kExternalWork], 0.5 * (3.0 * 0.25 - 1.0 * 0.5));
  EXPECT_EQ(w[kHourglassWork], 0.5 * (-2.0 * 0.25 + 4.0 * 0.5));
  EXPECT_EQ(w[kDampingWork], 0.5 * (1.0 * 0.25 + 3.0 * 0.5));  // dissipated: positive
  const DriftWork<2> none;
  std::array<double, 3> nothing = {0.0, 0.0, 0.0};
  none.addHalf(nothing, 1, du);
  EXPECT_EQ(nothing, (std::array<double, 3>{0.0, 0.0, 0.0}));
}

namespace {

// A free 2D block at rest, 12 x 4 particles, and what the books say after `steps` steps.
struct BlockRun {
  EnergyBalance first, last;
  double worstImbalance = 0.0;  // max |total - total(0)| over the run
  bool monotoneDamped = true;
};

template <class Setup>
BlockRun runBlock(int steps, Setup setup) {
  auto scene = sceneOf<2>(cellCentredLattice<2>(Vec<2>::Zero(), {12, 4}, 0.01), 0.01, 2.5,
                          testMaterial("neo-hookean"), 1.0);
  setup(scene);
  Solver<2> solver(scene);
  BlockRun r;
  r.first = solver.energyBalance();
  double damped = r.first.damped;
  for (int s = 0; s < steps; ++s) {
    solver.step();
    const EnergyBalance e = solver.energyBalance();
    r.worstImbalance = std::max(r.worstImbalance, std::abs(e.total() - r.first.total()));
    r.monotoneDamped = r.monotoneDamped && e.damped >= damped;
    damped = e.damped;
    r.last = e;
  }
  return r;
}

// The energy the body holds at the end of a run.
double held(const EnergyBalance& e) {
  return e.kinetic + e.strain + e.hourglass;
}

}  // namespace

// A load that pulls the free end of a bar puts energy in: external work positive, and what the
// body holds is that work.
TEST(EnergyBooks, LoadPullingTheBodyIsWorkPutIn) {
  const BlockRun r = runBlock(400, [](Scene<2>& scene) {
    Load<2> pull;
    for (Index i = 0; i < scene.particles.size(); ++i)
      if (scene.particles.referencePosition[i].x() > 0.11) {
        pull.particles.push_back(i);
        pull.force.push_back(Vec<2>(5.0, 1.0));
      }
    scene.loads.push_back(pull);
  });
  EXPECT_GT(r.last.externalWork, 0.0);
  EXPECT_EQ(r.last.boundaryWork, 0.0);
  EXPECT_LT(r.worstImbalance, 1e-3 * r.last.externalWork);
  EXPECT_NEAR(held(r.last), r.last.externalWork, 1e-3 * r.last.externalWork);
}

// A prescribed column driven into the body does work on it: boundary work positive, held by
// the body.
TEST(EnergyBooks, PrescribedParticlesPushingTheBodyDoBoundaryWork) {
  const BlockRun r = runBlock(400, [](Scene<2>& scene) {
    Prescription<2> piston;
    piston.name = "piston";
    piston.motion = PrescribedMotion::Velocity;
    piston.value = Vec<2>(0.2, 0.0);
    piston.ramp.duration = 2e-3;
    for (const auto& X : cellCentredLattice<2>(Vec<2>(-0.03, 0.0), {3, 4}, 0.01))
      piston.particles.push_back(scene.particles.add(X, 1e-4, 0.1, 0, Motion::Prescribed));
    scene.prescriptions.push_back(piston);
  });
  EXPECT_GT(r.last.boundaryWork, 0.0);
  EXPECT_EQ(r.last.externalWork, 0.0);
  EXPECT_LT(r.worstImbalance, 1e-2 * r.last.boundaryWork);
}

// Viscous damping only takes energy out, step by step, and the books still balance.
TEST(EnergyBooks, ViscousDampingTakesEnergyOut) {
  const BlockRun r = runBlock(400, [](Scene<2>& scene) {
    scene.damping.viscous = 200.0;
    for (Index i = 0; i < scene.particles.size(); ++i)
      scene.particles.velocity[i][1] = 0.5 * scene.particles.referencePosition[i].x();
  });
  EXPECT_TRUE(r.monotoneDamped);
  EXPECT_GT(r.last.damped, 0.1 * r.first.kinetic);
  EXPECT_LT(held(r.last), held(r.first));
  EXPECT_LT(r.worstImbalance, 1e-3 * r.first.kinetic);
}

// The artificial viscosity dissipates: booked as damping, positive.
TEST(EnergyBooks, ArtificialViscosityIsBookedAsDamping) {
  const BlockRun r = runBlock(400, [](Scene<2>& scene) {
    scene.viscosity.linear = 1.0;
    scene.viscosity.quadratic = 2.0;
    for (Index i = 0; i < scene.particles.size(); ++i)
      scene.particles.velocity[i][0] = -2.0 * (scene.particles.referencePosition[i].x() - 0.06);
  });
  EXPECT_GT(r.last.damped, 1e-3 * r.first.kinetic);
  EXPECT_LT(r.worstImbalance, 1e-2 * r.first.kinetic);
}

// A static step books the work of the loads and prescribed particles with the trapezoidal rule
// between two equilibria; the first one starts from the unloaded state.
TEST(EnergyBooks, StaticStepBooksTheTrapezoidalWorkFromTheUnloadedState) {
  ParticleSet<2> p;
  p.add(Vec<2>(0.0, 0.0), 1.0, 1.0, 0);                      // free, loaded
  p.add(Vec<2>(1.0, 0.0), 1.0, 1.0, 0, Motion::Prescribed);  // prescribed
  std::vector<Vec<2>> external = {Vec<2>(0.0, 0.0), Vec<2>(0.0, 0.0)};
  const std::vector<Index> free = {0}, prescribed = {1};
  EnergyBooks books;
  StaticStepBooks<2> step;
  p.force[1] = Vec<2>(7.0, 0.0);  // left over from before: ignored, the books start unloaded
  step.begin(p, external, {}, 0.0);
  EXPECT_TRUE(step.started && step.fromZero);
  external[0] = Vec<2>(2.0, 4.0);
  p.displacement[0] = Vec<2>(0.5, 0.25);
  p.displacement[1] = Vec<2>(-0.1, 0.0);
  p.force[1] = Vec<2>(3.0, 0.0);
  step.finish(books, p, external, {}, free, prescribed, {});
  EXPECT_DOUBLE_EQ(books.externalWork, 0.5 * (2.0 * 0.5 + 4.0 * 0.25));
  EXPECT_DOUBLE_EQ(books.boundaryWork, -0.5 * 3.0 * -0.1);  // pushed back: positive
  // The next step starts from the state the first ended in.
  step.begin(p, external, {}, 1.0);
  EXPECT_FALSE(step.fromZero);
  external[0] = Vec<2>(4.0, 8.0);
  p.displacement[0] = Vec<2>(1.0, 0.5);
  step.finish(books, p, external, {}, free, prescribed, {});
  EXPECT_DOUBLE_EQ(books.externalWork, 1.0 + 0.5 * (6.0 * 0.5 + 12.0 * 0.25));
  // Abandoning a later step keeps the books started; abandoning the first does not.
  step.abandon();
  EXPECT_TRUE(step.started);
  StaticStepBooks<2> fresh;
  fresh.begin(p, external, {}, 0.0);
  fresh.abandon();
  EXPECT_FALSE(fresh.started);
}

namespace {

// A strip 0.1 x 0.02 (gmsh) clamped at its left end under a pressure on its top raised over
// 0.01 s, undamped, for `steps` steps at `cfl`: the books' worst imbalance relative to the
// largest kinetic + strain energy, and the work booked.
std::pair<double, double> pressedStrip(bool follow, int steps, double cfl) {
  const fs::path dir = fs::temp_directory_path() / ("tlsph_books_strip_" + std::to_string(follow));
  fs::create_directories(dir);
  std::ofstream(dir / "strip.geo")
      << "SetFactory(\"OpenCASCADE\");\nRectangle(1) = {0, 0, 0, 0.1, 0.02};\ne = 1e-6;\n"
         "Physical Curve(\"top\") = Curve In BoundingBox{-e, 0.02 - e, -e, 0.1 + e, 0.02 + e, "
         "e};\nPhysical Curve(\"left\") = Curve In BoundingBox{-e, -e, -e, e, 0.02 + e, e};\n"
         "Physical Surface(\"strip\") = {1};\n";
  const std::string text =
      "[scene]\ndimension = 2\ndx = 0.005\n[material.rubber]\nmodel = neo-hookean\ndensity = "
      "1000\nyoungs_modulus = 1e6\npoisson_ratio = 0.3\n[body.b]\nshape = mesh\nfile = strip.geo\n"
      "[clamp.c]\nsurface = left\n[load.p]\nsurface = top\ntype = pressure\nvalue = 1e3\n"
      "ramp = 0.01\nfollow = " +
      std::string(follow ? "true" : "false") + "\n[time]\nend = 1\ncfl = " + std::to_string(cfl) +
      "\n";
  auto setup = buildScene<2>(Config::parse(text, (dir / "s.ini").string()));
  fs::remove_all(dir);
  Solver<2> solver(setup.scene, setup.solver);
  double worst = 0.0, largest = 0.0;
  for (int s = 0; s < steps; ++s) {
    solver.step();
    const EnergyBalance e = solver.energyBalance();
    largest = std::max(largest, e.kinetic + e.strain + e.hourglass);
    worst = worseOf(worst, std::abs(e.total()));
  }
  return {worst / largest, solver.energyBalance().externalWork};
}

}  // namespace

// A following pressure on an open surface has no potential: its work is the integral of
// f . du with the force of the present shape, which keeps the books; the dead pressure does
// other work over the same bending (so the books can tell them apart).
TEST(EnergyBooks, FollowingPressureIsBookedByItsWorkAlongThePath) {
  const auto [coarse, work] = pressedStrip(true, 1500, 0.3);
  const auto [fine, workFine] = pressedStrip(true, 3000, 0.15);
  std::printf("following pressure: books %.3g (cfl 0.3), %.3g (cfl 0.15)\n", coarse, fine);
  EXPECT_LT(coarse, 1e-3);
  EXPECT_LT(fine, 0.5 * coarse);  // the time discretisation's error, second order
  const auto [dead, deadWork] = pressedStrip(false, 1500, 0.3);
  EXPECT_LT(dead, 1e-3);
  EXPECT_GT(std::abs(work - deadWork), 1e-3 * std::abs(deadWork));
  (void)workFine;
}
