// The integrator (velocity Verlet, kick-drift-kick): a free step conserves linear momentum, a
// constant force gives the exact parabola, and the trajectory converges with the second order
// in dt.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "TestSupport.hpp"
#include "explicit/Solver.hpp"

using namespace tlsph;
using namespace tlsph::testing;

namespace {

constexpr double kDx = 0.01;

// A free, jittered 2D block with a smooth transverse velocity plus noise, so that the internal
// forces are large and uneven; `drift` adds a common velocity (nonzero momentum).
Scene<2> swingingBlock(const Vec<2>& drift = Vec<2>::Zero()) {
  std::mt19937 rng(7);
  auto scene = sceneOf<2>(perturbedBlock<2>({12, 6}, kDx, 0.1, rng), kDx, 2.5,
                          testMaterial("neo-hookean"), 1.0);
  const double c = waveSpeed(scene.materials[0]);
  auto& p = scene.particles;
  for (Index i = 0; i < p.size(); ++i) {
    p.velocity[i][1] = 0.05 * c * std::cos(M_PI * p.referencePosition[i].x() / (12 * kDx));
    p.velocity[i] += randomVector<2>(rng, 0.01 * c) + drift;
  }
  return scene;
}

// The largest |u_a - u_b| over the particles, relative to the largest |u_a|.
double fieldDifference(const std::vector<Vec<2>>& a, const std::vector<Vec<2>>& b) {
  double diff = 0.0, size = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    diff = std::max(diff, (a[i] - b[i]).norm());
    size = std::max(size, a[i].norm());
  }
  return diff / size;
}

// The displacements at time T, reached in `steps` equal steps.
std::vector<Vec<2>> displacementsAt(double T, int steps) {
  Scene<2> scene = swingingBlock();
  SolverSettings settings;
  settings.timeStep = T / steps;
  Solver<2> solver(scene, settings);
  for (int s = 0; s < steps; ++s)
    solver.step();
  EXPECT_NEAR(solver.time(), T, 1e-12 * T);
  return scene.particles.displacement;
}

}  // namespace

// Internal forces come in equal and opposite pairs, so each step changes no momentum: the
// kicks only move it between particles, to the rounding of the sums.
TEST(Solver, FreeStepConservesLinearMomentum) {
  const Vec<2> drift(3.0, -2.0);
  Scene<2> scene = swingingBlock(drift);
  Solver<2> solver(scene);
  const Vec<2> before = linearMomentum(scene.particles);
  double scale = 0.0;  // the momentum the particles carry one by one
  for (Index i = 0; i < scene.particles.size(); ++i)
    scale += scene.particles.mass[i] * scene.particles.velocity[i].norm();
  double forces = 0.0;
  for (int s = 0; s < 50; ++s) {
    solver.step();
    for (const auto& f : scene.particles.force)
      forces = std::max(forces, f.norm());
    EXPECT_LT((linearMomentum(scene.particles) - before).norm(), 1e-13 * scale) << "step " << s;
  }
  // The internal forces are not negligible: each one alone would change the momentum.
  EXPECT_GT(forces * solver.timeStep(), 1e-4 * scale / scene.particles.size());
}

// A body in uniform motion under gravity feels no internal force (F = I), and velocity Verlet
// integrates a constant force exactly: u = v0 t + g t^2 / 2.
TEST(Solver, ConstantForceGivesTheExactParabola) {
  std::mt19937 rng(3);
  auto scene = sceneOf<3>(perturbedBlock<3>({4, 3, 3}, kDx, 0.1, rng), kDx, 2.5,
                          testMaterial("saint-venant-kirchhoff"), 1.0);
  const Vec<3> g(0.0, -9.81, 2.0), v0(0.5, 1.0, -0.25);
  scene.gravity = g;
  for (auto& v : scene.particles.velocity)
    v = v0;
  Solver<3> solver(scene);
  for (int s = 0; s < 200; ++s)
    solver.step();
  const double t = solver.time();
  const Vec<3> u = v0 * t + 0.5 * g * t * t;
  ASSERT_GT(u.norm(), 1e-3);
  for (Index i = 0; i < scene.particles.size(); ++i) {
    EXPECT_LT((scene.particles.displacement[i] - u).norm(), 1e-12 * u.norm()) << i;
    EXPECT_LT((scene.particles.velocity[i] - (v0 + g * t)).norm(), 1e-12 * (v0 + g * t).norm());
  }
}

// Halving dt reduces the error by four: the differences of the runs at dt, dt/2, dt/4 shrink
// by that factor (Richardson), and the step is far from its stability limit's transients.
TEST(Solver, VelocityVerletIsSecondOrderInTheTimeStep) {
  Scene<2> probe = swingingBlock();
  const double dt = Solver<2>(probe).timeStep();
  const double T = 40 * dt;
  const auto u1 = displacementsAt(T, 40);
  const auto u2 = displacementsAt(T, 80);
  const auto u4 = displacementsAt(T, 160);
  const double coarse = fieldDifference(u1, u2), fine = fieldDifference(u2, u4);
  std::cout << "|u(dt) - u(dt/2)| = " << coarse << ", |u(dt/2) - u(dt/4)| = " << fine << ", ratio "
            << coarse / fine << "\n";
  EXPECT_GT(coarse, 1e-9);  // the time step matters at all
  EXPECT_GT(coarse / fine, 3.5);
  EXPECT_LT(coarse / fine, 4.5);
}
