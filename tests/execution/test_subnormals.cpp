// The explicit step computes with subnormal numbers as zero (SubnormalsToZero.hpp):
// the guard sets and restores the mode on every thread, and a wave's precursor running into
// a body at rest leaves no subnormal value in the state, where without the guard it does.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "TestSupport.hpp"
#include "execution/SubnormalsToZero.hpp"
#include "explicit/Solver.hpp"

using namespace tlsph;
using namespace tlsph::testing;

namespace {

// min_normal / 4 times one: a subnormal operand and a subnormal result, unless flushed. The
// volatile operands keep the compiler from folding the product.
double subnormalProduct() {
  volatile double tiny = std::numeric_limits<double>::min() / 4.0;
  volatile double one = 1.0;
  return tiny * one;
}

template <int D>
long subnormalsIn(const std::vector<Vec<D>>& values) {
  long count = 0;
  for (const auto& v : values)
    for (int a = 0; a < D; ++a)
      count += std::fpclassify(v[a]) == FP_SUBNORMAL;
  return count;
}

}  // namespace

TEST(SubnormalsToZero, FlushesOnEveryThreadAndRestoresAfterwards) {
  if (!SubnormalsToZero::supported()) GTEST_SKIP() << "no flush-to-zero mode on this target";
  ASSERT_EQ(std::fpclassify(subnormalProduct()), FP_SUBNORMAL);  // the default mode
#ifdef _OPENMP
  const int threadsBefore = omp_get_max_threads();
  omp_set_num_threads(3);
#endif
  {
    const SubnormalsToZero guard;
    int flushed = 0, threads = 0;
#pragma omp parallel reduction(+ : flushed, threads)
    {
      flushed += subnormalProduct() == 0.0;
      threads += 1;
    }
    EXPECT_EQ(flushed, threads);
    {
      const SubnormalsToZero inner;  // restores "flushing", not the default
    }
    EXPECT_EQ(subnormalProduct(), 0.0);
  }
  int kept = 0, threads = 0;
#pragma omp parallel reduction(+ : kept, threads)
  {
    kept += std::fpclassify(subnormalProduct()) == FP_SUBNORMAL;
    threads += 1;
  }
  EXPECT_EQ(kept, threads);
#ifdef _OPENMP
  omp_set_num_threads(threadsBefore);
#endif
}

namespace {

Scene<2> droppedStrip() {
  const double dx = 0.01;
  auto scene = sceneOf<2>(cellCentredLattice<2>(Vec<2>(0, 0), {160, 4}, dx), dx, 2.1,
                          testMaterial("neo-hookean"), 5.0);
  for (Index i = 0; i < scene.particles.size(); ++i)
    if (scene.particles.referencePosition[i].x() < 3 * dx)
      scene.particles.motion[i] = Motion::Prescribed;
  scene.gravity = Vec<2>(0.0, -9.81);
  return scene;
}

}  // namespace

// A strip clamped at one end and dropped under gravity: the clamp's disturbance runs along
// it one support radius per step, its precursor falling by about 10^-8 per hop, so within
// 60 steps values pass through the subnormal range (the same run without the guard in
// Solver::step leaves hundreds of them in the forces and velocities).
TEST(SubnormalsToZero, AWavePrecursorLeavesNoSubnormalInTheState) {
  if (!SubnormalsToZero::supported()) GTEST_SKIP() << "no flush-to-zero mode on this target";
  auto scene = droppedStrip();
  Solver<2> solver(scene);
  long subnormals = 0;
  for (int s = 0; s < 60; ++s) {
    solver.step();
    subnormals += subnormalsIn<2>(scene.particles.displacement) +
                  subnormalsIn<2>(scene.particles.velocity) +
                  subnormalsIn<2>(scene.particles.force);
  }
  EXPECT_EQ(subnormals, 0);
  // and the front has moved: the clamp's neighbours carry a nonzero relative displacement
  const auto& u = scene.particles.displacement;
  EXPECT_NE(u[3].y(), u.back().y());
}

// A restart recomputes the forces of the state it restores (Solver::restore): in the step's
// mode, so they are the bits the uninterrupted run had, subnormals flushed alike (frames
// written after a restart equal the uninterrupted run's), and the run continues bit for bit.
TEST(SubnormalsToZero, ARestoredStateHasTheForcesTheStepComputed) {
  if (!SubnormalsToZero::supported()) GTEST_SKIP() << "no flush-to-zero mode on this target";
  auto scene = droppedStrip();
  Solver<2> solver(scene);
  std::vector<SolverState<2>> states;
  std::vector<std::vector<Vec<2>>> forces;
  for (int s = 0; s < 60; ++s) {
    solver.step();
    states.push_back(solver.state());
    forces.push_back(scene.particles.force);
  }
  const auto end = scene.particles.displacement;
  for (int s : {20, 30, 40}) {
    solver.restore(states[s]);
    ASSERT_EQ(scene.particles.force, forces[s]) << "restored at step " << s + 1;
  }
  solver.restore(states[29]);
  for (int s = 30; s < 60; ++s)
    solver.step();
  EXPECT_EQ(scene.particles.displacement, end);
}
