// The Newton static solver ([static] solver = newton): it reaches the same equilibrium as the
// damped explicit solver, closes the energy books of a linear problem exactly (Clapeyron: the
// work of loads raised from zero equals the stored energy), balances the loads with the
// clamp's reaction, follows geometrically nonlinear load paths in load steps, and fails with a
// message that names the load and the reason. With a following pressure (its tangent not
// symmetric, solved by BiCGSTAB) Newton still converges quadratically to the damped solver's
// equilibrium, which differs from the dead pressure's.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "app/RunSimulation.hpp"
#include "implicit/NewtonSolver.hpp"
#include "scene/Config.hpp"
#include "scene/InputError.hpp"
#include "scene/SceneBuilder.hpp"

using namespace tlsph;
namespace fs = std::filesystem;

namespace {

// A plane-strain cantilever 0.4 x 0.05 m (dx = 0.0125: 32 x 4), clamped at x = 0 by mirrored
// ghosts, under gravity.
std::string beam(const std::string& model, double gravity, const std::string& extra = "") {
  return R"([scene]
dimension = 2
dx = 0.0125
[material.rubber]
model = )" +
         model + R"(
density = 1000
youngs_modulus = 1.0e6
poisson_ratio = 0.3
[body.beam]
shape = box
lower = 0 0
upper = 0.4 0.05
[clamp.root]
face = x-
[gravity]
acceleration = 0 )" +
         std::to_string(-gravity) + R"(
[damping]
kinetic = true
[time]
end = 20
[output]
fields = none
)" + extra;
}

struct Result {
  RunSummary summary;
  SceneSetup<2> setup;
};

Result run(const std::string& text, const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("tlsph_newton_" + name);
  fs::remove_all(dir);
  Result r{
      {},
      buildScene<2>(Config::parse(text, name + ".ini", {"--output.directory=" + dir.string()}))};
  r.summary = runSimulation(r.setup, RunOptions{}, [](const Solver<2>&) {});
  fs::remove_all(dir);
  return r;
}

double largestDisplacement(const SceneSetup<2>& s) {
  double m = 0.0;
  for (const auto& u : s.scene.particles.displacement)
    m = std::max(m, u.norm());
  return m;
}

double largestDifference(const SceneSetup<2>& a, const SceneSetup<2>& b) {
  double m = 0.0;
  for (std::size_t i = 0; i < a.scene.particles.displacement.size(); ++i)
    m = std::max(m, (a.scene.particles.displacement[i] - b.scene.particles.displacement[i]).norm());
  return m;
}

TEST(NewtonStatic, AgreesWithTheDampedSolver) {
  for (const std::string model : {"linear-elastic", "neo-hookean"}) {
    const Result damped = run(beam(model, 1.0, "[static]\ntolerance = 1e-8\n"), "damped");
    const Result newton =
        run(beam(model, 1.0, "[static]\ntolerance = 1e-8\nsolver = newton\n"), "newton");
    ASSERT_EQ(damped.summary.outcome, RunOutcome::Converged) << model;
    ASSERT_EQ(newton.summary.outcome, RunOutcome::Converged) << model;
    EXPECT_LE(newton.summary.residual, 1e-8);
    // Both at residual 1e-8 of the load: the displacements agree to about that times the
    // beam's flexibility ratio (tip deflection / length ~ 1e-2 .. 1e-1).
    EXPECT_LT(largestDifference(damped.setup, newton.setup),
              1e-5 * largestDisplacement(newton.setup))
        << model;
    EXPECT_LE(newton.summary.newton->iterations, 6) << model;
  }
}

TEST(NewtonStatic, LinearProblemClosesTheEnergyBooks) {
  for (int steps : {1, 3}) {
    const Result r = run(beam("linear-elastic", 1.0,
                              "[static]\nsolver = newton\ntolerance = 1e-9\nload_steps = " +
                                  std::to_string(steps) + "\n[gravity]\nramp = 1\n"),
                         "clapeyron");
    ASSERT_EQ(r.summary.outcome, RunOutcome::Converged);
    const EnergyBalance& e = r.summary.energy;
    const double stored = e.strain + e.hourglass;
    EXPECT_GT(stored, 0.0);
    // Clapeyron: loads raised from zero on a linear body do work equal to the stored energy
    // (1/2 f . u), which the trapezoidal books get exactly for any number of load steps.
    EXPECT_NEAR(e.externalWork, stored, 1e-9 * stored) << steps << " load steps";
    EXPECT_NEAR(e.total(), 0.0, 1e-9 * stored);
    EXPECT_EQ(r.summary.newton->loadSteps, steps);
  }
}

TEST(NewtonStatic, ClampReactionBalancesTheWeight) {
  const Result r =
      run(beam("neo-hookean", 1.0, "[static]\nsolver = newton\ntolerance = 1e-9\n"), "reaction");
  ASSERT_EQ(r.summary.outcome, RunOutcome::Converged);
  double weight = 0.0;
  for (Index i = 0; i < r.setup.scene.particles.size(); ++i)
    if (r.setup.scene.particles.motion[i] == Motion::Free)
      weight += r.setup.scene.particles.mass[i];
  ASSERT_EQ(r.summary.finalReactions.size(), 1u);
  const Vec3 R = r.summary.finalReactions[0].second;
  EXPECT_NEAR(R.y(), weight * 1.0, 1e-6 * weight);
  EXPECT_NEAR(R.x(), 0.0, 1e-6 * weight);
}

TEST(NewtonStatic, FollowsALargeDeflectionInLoadSteps) {
  // Gravity 400 m/s^2 on a soft beam: the tip swings down by a third of the length.
  const std::string extra = "[gravity]\nramp = 1\n";
  const Result newton = run(beam("neo-hookean", 400.0,
                                 extra + "[static]\nsolver = newton\ntolerance = 1e-8\n"
                                         "load_steps = 4\n"),
                            "large_newton");
  ASSERT_EQ(newton.summary.outcome, RunOutcome::Converged) << newton.summary.message;
  const double tip = largestDisplacement(newton.setup);
  EXPECT_GT(tip, 0.1);
  const Result damped =
      run(beam("neo-hookean", 400.0, extra + "[static]\ntolerance = 1e-8\n"), "large_damped");
  ASSERT_EQ(damped.summary.outcome, RunOutcome::Converged);
  EXPECT_LT(largestDifference(damped.setup, newton.setup), 1e-5 * tip);
}

TEST(NewtonStatic, FailureNamesTheLoadAndTheReason) {
  const Result r = run(beam("neo-hookean", 400.0,
                            "[gravity]\nramp = 1\n[static]\nsolver = newton\nmax_iterations = "
                            "1\ntolerance = 1e-8\n"),
                       "failure");
  EXPECT_EQ(r.summary.outcome, RunOutcome::NotConverged);
  EXPECT_NE(r.summary.message.find("no equilibrium at load time"), std::string::npos)
      << r.summary.message;
  EXPECT_NE(r.summary.message.find("not converged in 1 iterations"), std::string::npos)
      << r.summary.message;
  // The state left behind is the last converged one: the unloaded start.
  EXPECT_EQ(r.summary.newton->loadSteps, 0);
  EXPECT_DOUBLE_EQ(largestDisplacement(r.setup), 0.0);
}

// A neo-Hookean rubber (E = 1 MPa) meshed from `geometry`, clamped on `clamp`, under a
// pressure p on `loaded`, following or dead.
std::string pressureScene(const std::string& geometry, double dx, const std::string& clamp,
                          const std::string& loaded, double p, bool follow,
                          const std::string& extra = "") {
  return "[scene]\ndimension = 2\ndx = " + std::to_string(dx) +
         "\n[material.rubber]\nmodel = neo-hookean\ndensity = 1000\nyoungs_modulus = 1.0e6\n"
         "poisson_ratio = 0.3\n[body.b]\nshape = mesh\nfile = " +
         geometry + "\n[clamp.c]\nsurface = " + clamp + "\n[load.p]\nsurface = " + loaded +
         "\ntype = pressure\nvalue = " + std::to_string(p) +
         "\nfollow = " + (follow ? "true" : "false") +
         "\n[damping]\nkinetic = true\n[static]\ntolerance = 1e-8\n[time]\nend = 20\n"
         "[output]\nfields = none\n" +
         extra;
}

// Newton on the scene directly (for its residual history).
struct NewtonRun {
  SceneSetup<2> setup;
  std::vector<double> history;
  NewtonStatistics statistics;
};

NewtonRun newtonOn(const std::string& text) {
  NewtonRun r{buildScene<2>(Config::parse(text, "newton.ini")), {}, {}};
  Solver<2> solver(r.setup.scene, r.setup.solver);
  NewtonSolver<2> newton(r.setup.scene, solver, r.setup.run.newton, r.setup.coarsen,
                         r.setup.solver);
  newton.run([] { return true; });
  r.history = newton.residualHistory();
  r.statistics = newton.statistics();
  return r;
}

// The ratio of each residual to the square of the one before, over the iterations that start
// below `below` and end above `floor` (where the linear solves' tolerance, 0.1 times the Newton
// tolerance, takes over): bounded for quadratic convergence.
double quadraticConstant(const std::vector<double>& h, double below, double floor) {
  double worst = 0.0;
  for (std::size_t k = 0; k + 1 < h.size(); ++k)
    if (h[k] < below && h[k + 1] > floor) worst = std::max(worst, h[k + 1] / (h[k] * h[k]));
  return worst;
}

void expectFollowingNewtonMatchesDamped(const std::string& name, const std::string& geometry,
                                        double dx, const std::string& clamp,
                                        const std::string& loaded, double p, double minStrain) {
  const NewtonRun newton = newtonOn(pressureScene(geometry, dx, clamp, loaded, p, true));
  std::string history;
  char number[32];
  for (double r : newton.history) {
    std::snprintf(number, sizeof number, " %.2e", r);
    history += number;
  }
  std::printf("%s: following pressure, Newton residual ratios:%s\n", name.c_str(), history.c_str());
  ASSERT_LE(newton.history.back(), 1e-8) << history;
  EXPECT_LE(newton.history.size(), 8u) << history;
  EXPECT_NE(newton.statistics.linearSolver.find("BiCGSTAB"), std::string::npos)
      << newton.statistics.linearSolver;
  // Quadratic: each residual below 1e-2 is followed by one below 10 times its square (ring:
  // 2.4e-3 -> 7.6e-7; strip: 1.2e-3 -> 4.5e-6), down to the linear solves' floor.
  EXPECT_LT(quadraticConstant(newton.history, 1e-2, 1e-9), 10.0) << history;
  const double largest = largestDisplacement(newton.setup);
  EXPECT_GT(largest, minStrain * dx) << "the deformation should matter";

  const Result damped = run(pressureScene(geometry, dx, clamp, loaded, p, true), name + "_damped");
  ASSERT_EQ(damped.summary.outcome, RunOutcome::Converged) << damped.summary.message;
  const double toDamped = largestDifference(damped.setup, newton.setup);
  std::printf("%s: |u_newton - u_damped|max / |u|max = %.3g (%ld damped steps)\n", name.c_str(),
              toDamped / largest, damped.summary.steps);
  EXPECT_LT(toDamped, 1e-5 * largest);

  const NewtonRun dead = newtonOn(pressureScene(geometry, dx, clamp, loaded, p, false));
  const double toDead = largestDifference(dead.setup, newton.setup);
  std::printf("%s: |u_following - u_dead|max / |u|max = %.3g\n", name.c_str(), toDead / largest);
  EXPECT_GT(toDead, 1e-2 * largest);
}

// The thick ring of the Lame problem (validation/geometry/lame_ring.geo), outer surface clamped,
// 100 kPa in the bore: about 6 % hoop strain at the bore, so the bore's growth adds to the
// following load. The bore is closed: the load stiffness is symmetric there.
TEST(NewtonStatic, FollowingPressureInARingConvergesQuadraticallyToTheDampedEquilibrium) {
  expectFollowingNewtonMatchesDamped(
      "ring", std::string(TLSPH_SOURCE_DIR) + "/validation/geometry/lame_ring.geo", 0.0125, "outer",
      "bore", 1.0e5, 0.1);
}

// A strip 0.1 x 0.02 clamped at its left end, pressed on its top: a follower load on an open
// surface (not conservative, its stiffness not symmetric) that turns with the bending.
TEST(NewtonStatic, FollowingPressureOnABentStripConvergesQuadraticallyToTheDampedEquilibrium) {
  const fs::path dir = fs::temp_directory_path() / "tlsph_newton_following_strip";
  fs::create_directories(dir);
  std::ofstream(dir / "strip.geo")
      << "SetFactory(\"OpenCASCADE\");\nRectangle(1) = {0, 0, 0, 0.1, 0.02};\ne = 1e-6;\n"
         "Physical Curve(\"top\") = Curve In BoundingBox{-e, 0.02 - e, -e, 0.1 + e, 0.02 + e, "
         "e};\nPhysical Curve(\"left\") = Curve In BoundingBox{-e, -e, -e, e, 0.02 + e, e};\n"
         "Physical Surface(\"strip\") = {1};\n";
  expectFollowingNewtonMatchesDamped("strip", (dir / "strip.geo").string(), 0.005, "left", "top",
                                     1.0e3, 1.0);
  fs::remove_all(dir);
}

TEST(NewtonStatic, InputErrors) {
  EXPECT_THROW(
      buildScene<2>(Config::parse(
          beam("neo-hookean", 1.0, "[static]\nsolver = newton\nload_steps = 0\n"), "bad.ini")),
      InputError);
  EXPECT_THROW(buildScene<2>(Config::parse(
                   beam("neo-hookean", 1.0,
                        "[static]\nsolver = newton\n[hourglass]\nform = ganzenmueller\n"),
                   "bad.ini")),
               InputError);
  EXPECT_THROW(
      buildScene<2>(Config::parse(beam("neo-hookean", 1.0, "[static]\nsolver = cg\n"), "bad.ini")),
      InputError);
}

}  // namespace
