// Each particle gathers its own sums over a full neighbour list, and sums over all particles
// (energy books, the kinetic energy kinetic damping watches) are taken in a fixed order, so a
// step gives bitwise the same result whatever the number of OpenMP threads.
#include <gtest/gtest.h>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "TestSupport.hpp"
#include "explicit/Solver.hpp"

using namespace tlsph;
using namespace tlsph::testing;

namespace {

struct Outcome {
  std::vector<Vec3> displacement;
  EnergyBalance books;
};

Outcome runWithThreads(int threads, bool kineticDamping = false) {
#ifdef _OPENMP
  omp_set_num_threads(threads);
#else
  (void)threads;
#endif
  std::mt19937 rng(51);
  const double dx = 0.01;
  auto scene = sceneOf<3>(perturbedBlock<3>({12, 5, 5}, dx, 0.1, rng), dx, 2.1,
                          testMaterial("neo-hookean"), 5.0);
  scene.gravity = Vec3(0.0, 0.0, -9.81);
  for (auto& v : scene.particles.velocity)
    v = randomVector<3>(rng, 0.5);
  scene.damping.kinetic = kineticDamping;
  Solver<3> solver(scene);
  for (int s = 0; s < 50; ++s)
    solver.step();
  return {scene.particles.displacement, solver.energyBalance()};
}

void expectBitwiseEqual(const Outcome& a, const Outcome& b, int threads) {
  ASSERT_EQ(a.displacement.size(), b.displacement.size());
  for (std::size_t i = 0; i < a.displacement.size(); ++i)
    ASSERT_EQ(a.displacement[i], b.displacement[i]) << "particle " << i << ", " << threads;
  // The books are sums over all particles, taken in a fixed order (OrderedSum.hpp).
  EXPECT_EQ(a.books.kinetic, b.books.kinetic) << threads << " threads";
  EXPECT_EQ(a.books.strain, b.books.strain) << threads << " threads";
  EXPECT_EQ(a.books.hourglass, b.books.hourglass) << threads << " threads";
  EXPECT_EQ(a.books.externalWork, b.books.externalWork) << threads << " threads";
  EXPECT_EQ(a.books.damped, b.books.damped) << threads << " threads";
}

}  // namespace

TEST(ThreadIndependence, AnyThreadCountGivesBitwiseEqualResults) {
  const Outcome one = runWithThreads(1);
  for (int threads : {2, 3, 5})
    expectBitwiseEqual(one, runWithThreads(threads), threads);
}

// Kinetic damping compares the kinetic energy (a sum over all particles) with its previous
// value: the same decisions on any thread count.
TEST(ThreadIndependence, KineticDampingDecidesAlikeOnAnyThreadCount) {
  const Outcome one = runWithThreads(1, true);
  for (int threads : {2, 3})
    expectBitwiseEqual(one, runWithThreads(threads, true), threads);
}
