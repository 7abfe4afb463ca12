// Each particle gathers its own sums over a full neighbour list, so a step gives bitwise the
// same result whatever the number of OpenMP threads.
#include <gtest/gtest.h>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "TestSupport.hpp"
#include "tlsph/Solver.hpp"

using namespace tlsph;
using namespace tlsph::testing;

namespace {

std::vector<Vec3> runWithThreads(int threads) {
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
  Solver<3> solver(scene);
  for (int s = 0; s < 50; ++s)
    solver.step();
  return scene.particles.displacement;
}

}  // namespace

TEST(ThreadIndependence, OneAndTwoThreadsGiveBitwiseEqualResults) {
  const auto one = runWithThreads(1);
  const auto two = runWithThreads(2);
  ASSERT_EQ(one.size(), two.size());
  for (std::size_t i = 0; i < one.size(); ++i)
    ASSERT_EQ(one[i], two[i]) << "particle " << i;
}
