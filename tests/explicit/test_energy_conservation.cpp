// An undamped free vibration keeps the energy books balanced and the linear momentum exact.
#include <gtest/gtest.h>

#include <cmath>

#include "TestSupport.hpp"
#include "explicit/Solver.hpp"

using namespace tlsph;
using namespace tlsph::testing;

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
TEST(EnergyConservation, FreeVibration2D) {
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

TEST(EnergyConservation, FreeVibration3D) {
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

TEST(EnergyConservation, WithoutHourglassTheBooksStillBalance) {
  const Drift d = freeVibration<2>("linear-elastic", 0.0, 3000);
  EXPECT_LT(d.energy, 1e-3);
  EXPECT_LT(d.momentum, 1e-12);
}

// The defaults (quadratic correction, energy-form penalty alpha = 10 on the same F): the same
// books, with E_hg a state function in them.
TEST(EnergyConservation, FreeVibrationQuadraticCorrection) {
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
