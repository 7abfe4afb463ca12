// The mirrored clamp (DESIGN.md section 3): ghosts take the odd reflection u_ghost = -u_mirror of
// the body particle mirrored across the face, carry no strain energy, and send their force back to
// the mirror particle. Then the force on the body is -dE/du of the body's energy (strain plus
// hourglass), an undamped run keeps its energy books balanced, and a field that vanishes on the
// face with odd symmetry is reproduced exactly by the ghosts.
#include <gtest/gtest.h>

#include "TestSupport.hpp"
#include "tlsph/Solver.hpp"

using namespace tlsph;
using namespace tlsph::testing;

namespace {

constexpr double kDx = 0.01;

// A 2D beam 0.16 x 0.04 m (16 x 4 particles) or a 3D one 0.08 x 0.03 x 0.03 (8 x 3 x 3),
// clamped at x = 0 by three mirrored ghost layers.
template <int D>
Scene<D> mirroredBeam(double alpha, GradientCorrection correction) {
  std::array<int, D> counts;
  counts.fill(D == 2 ? 4 : 3);
  counts[0] = D == 2 ? 16 : 8;
  const auto X = cellCentredLattice<D>(Vec<D>::Zero(), counts, kDx);
  Scene<D> scene = sceneOf<D>(X, kDx, 2.5, testMaterial("neo-hookean"), alpha);
  scene.gradientCorrection = correction;
  const double V = std::pow(kDx, D);
  const Index body = scene.particles.size();
  for (Index i = 0; i < body; ++i) {
    const Vec<D> Xi = scene.particles.referencePosition[i];
    const int layer = static_cast<int>(std::lround(Xi.x() / kDx - 0.5));  // 0, 1, 2, ...
    if (layer >= 3) continue;
    Vec<D> G = Xi;
    G.x() = -Xi.x();  // ghost layer k mirrors body layer k
    const Index g = scene.particles.add(G, V, 1000.0 * V, 0, Motion::Mirrored);
    scene.mirrorGhosts.push_back({g, i});
  }
  return scene;
}

template <int D>
void expectForceIsMinusBodyEnergyGradient(GradientCorrection correction, std::uint32_t seed) {
  std::mt19937 rng(seed);
  const Scene<D> base = mirroredBeam<D>(10.0, correction);
  std::vector<Index> body;
  for (Index i = 0; i < base.particles.size(); ++i)
    if (base.particles.motion[i] == Motion::Free) body.push_back(i);
  std::vector<Vec<D>> u(base.particles.size(), Vec<D>::Zero());
  const Mat<D> A = randomMatrix<D>(rng, 0.05);
  for (Index i : body)
    u[i] = A * base.particles.referencePosition[i] + randomVector<D>(rng, 0.03 * kDx);
  auto evaluate = [&](const std::vector<Vec<D>>& field, std::vector<Vec<D>>* force) {
    Scene<D> scene = base;
    scene.particles.displacement = field;
    Solver<D> solver(scene);  // sets the ghosts from the body and computes the forces
    if (force) *force = scene.particles.force;
    const EnergyBalance e = solver.energyBalance();
    return e.strain + e.hourglass;
  };
  std::vector<Vec<D>> f;
  evaluate(u, &f);
  double fmax = 0.0;
  for (Index i : body)
    fmax = std::max(fmax, f[i].cwiseAbs().maxCoeff());
  const double h = 1e-5 * kDx;
  double worst = 0.0;
  for (Index i : body)
    for (int a = 0; a < D; ++a) {
      const double saved = u[i][a];
      u[i][a] = saved + h;
      const double plus = evaluate(u, nullptr);
      u[i][a] = saved - h;
      const double minus = evaluate(u, nullptr);
      u[i][a] = saved;
      worst = std::max(worst, std::abs(-(plus - minus) / (2 * h) - f[i][a]));
    }
  EXPECT_LT(worst, 1e-6 * fmax) << D << "D";
}

struct Books {
  double error = 0.0;  // max |E_total(t) - E_total(0)| / peak strain energy
  double peakStrain = 0.0;
};

template <int D>
Books undampedVibration(double cfl, int steps) {
  Scene<D> scene = mirroredBeam<D>(10.0, GradientCorrection::Quadratic);
  const double c = waveSpeed(scene.materials[0]);
  for (Index i = 0; i < scene.particles.size(); ++i)
    if (scene.particles.motion[i] == Motion::Free) {
      const double s = scene.particles.referencePosition[i].x() / (D == 2 ? 0.16 : 0.08);
      scene.particles.velocity[i][1] = 0.02 * c * s * s;
    }
  SolverSettings settings;
  settings.cfl = cfl;
  Solver<D> solver(scene, settings);
  const double e0 = solver.energyBalance().total();
  Books b;
  double worst = 0.0;
  const int total = static_cast<int>(std::lround(steps * kDefaultCfl / cfl));
  for (int s = 1; s <= total; ++s) {
    solver.step();
    if (s % 20 == 0) {
      const EnergyBalance e = solver.energyBalance();
      worst = std::max(worst, std::abs(e.total() - e0));
      b.peakStrain = std::max(b.peakStrain, e.strain + e.hourglass);
    }
  }
  b.error = worst / b.peakStrain;
  return b;
}

}  // namespace

TEST(MirroredClamp, ForceIsMinusBodyEnergyGradient) {
  expectForceIsMinusBodyEnergyGradient<2>(GradientCorrection::Linear, 61);
  expectForceIsMinusBodyEnergyGradient<2>(GradientCorrection::Quadratic, 62);
  expectForceIsMinusBodyEnergyGradient<3>(GradientCorrection::Quadratic, 63);
}

TEST(MirroredClamp, UndampedVibrationKeepsTheEnergyBooks) {
  for (int d : {2, 3}) {
    const Books b =
        d == 2 ? undampedVibration<2>(kDefaultCfl, 3000) : undampedVibration<3>(kDefaultCfl, 2000);
    const Books half = d == 2 ? undampedVibration<2>(0.5 * kDefaultCfl, 3000)
                              : undampedVibration<3>(0.5 * kDefaultCfl, 2000);
    std::cout << d << "D mirrored clamp, alpha 10: energy-balance error " << b.error
              << " of the peak strain energy (" << half.error << " at dt/2)\n";
    EXPECT_GT(b.peakStrain, 0.0);
    EXPECT_LT(b.error, 1e-3);
    EXPECT_LT(half.error, b.error / 3.0);
  }
}

// u_x = a x + b x^2 y, u_y = c x (vanishing on x = 0, odd in x): the ghosts' values are the
// field's own at their positions, so every body particle next to the face sees the exact field
// and its F is exact (quadratic correction).
TEST(MirroredClamp, ReproducesAnOddFieldThatVanishesOnTheFace) {
  Scene<2> scene = mirroredBeam<2>(0.0, GradientCorrection::Quadratic);
  auto field = [](const Vec<2>& X) {
    return Vec<2>(0.02 * X.x() + 3.0 * X.x() * X.y(), -0.05 * X.x());
  };
  auto gradient = [](const Vec<2>& X) {
    Mat<2> G;
    G << 0.02 + 3.0 * X.y(), 3.0 * X.x(), -0.05, 0.0;
    return G;
  };
  for (Index i = 0; i < scene.particles.size(); ++i)
    if (scene.particles.motion[i] == Motion::Free)
      scene.particles.displacement[i] = field(scene.particles.referencePosition[i]);
  Solver<2> solver(scene);
  const auto& F = solver.forces().deformationGradient();
  double worstGhost = 0.0, worstF = 0.0;
  for (const auto& m : scene.mirrorGhosts) {
    const Vec<2> G = scene.particles.referencePosition[m.ghost];
    worstGhost = std::max(worstGhost, (scene.particles.displacement[m.ghost] - field(G)).norm());
  }
  for (Index i = 0; i < scene.particles.size(); ++i) {
    const Vec<2> X = scene.particles.referencePosition[i];
    if (scene.particles.motion[i] != Motion::Free || X.x() > 3 * kDx) continue;
    // interior in y only: the beam's top and bottom surfaces are free, the face is what counts
    worstF = std::max(worstF, (F[i] - Mat<2>::Identity() - gradient(X)).norm());
  }
  EXPECT_LT(worstGhost, 1e-15);
  EXPECT_LT(worstF, 1e-10);
}
