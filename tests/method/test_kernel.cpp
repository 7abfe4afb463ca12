// The kernels integrate to one and their gradients are the derivative of their values.
#include <gtest/gtest.h>

#include <random>

#include "geometry/Lattice.hpp"
#include "method/Kernel.hpp"

using namespace tlsph;

namespace {

template <int D>
double integrateOnLattice(const Kernel<D>& kernel, int cellsPerH) {
  const double H = kernel.supportRadius();
  const double dx = H / cellsPerH;
  std::array<int, D> counts;
  counts.fill(2 * cellsPerH);
  double sum = 0.0;
  for (const auto& x : cellCentredLattice<D>(Vec<D>::Constant(-H), counts, dx))
    sum += kernel.value(x.norm());
  return sum * std::pow(dx, D);
}

template <int D>
void expectGradientMatchesValue(const Kernel<D>& kernel) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const double H = kernel.supportRadius();
  const double step = 1e-6 * H;
  for (int trial = 0; trial < 200; ++trial) {
    Vec<D> x;
    for (int a = 0; a < D; ++a)
      x[a] = 0.6 * H * unit(rng);
    const Vec<D> g = kernel.gradient(x);
    for (int a = 0; a < D; ++a) {
      Vec<D> e = Vec<D>::Zero();
      e[a] = step;
      const double fd = (kernel.value((x + e).norm()) - kernel.value((x - e).norm())) / (2 * step);
      EXPECT_NEAR(g[a], fd, 1e-6 * kernel.value(0.0) / H)
          << "axis " << a << " at " << x.transpose();
    }
  }
}

}  // namespace

TEST(Kernel, WendlandIntegratesToOne2D) {
  EXPECT_NEAR(integrateOnLattice(Kernel<2>(KernelType::WendlandC2, 0.3), 40), 1.0, 1e-3);
}
TEST(Kernel, WendlandIntegratesToOne3D) {
  EXPECT_NEAR(integrateOnLattice(Kernel<3>(KernelType::WendlandC2, 0.3), 20), 1.0, 1e-3);
}
TEST(Kernel, CubicBSplineIntegratesToOne2D) {
  EXPECT_NEAR(integrateOnLattice(Kernel<2>(KernelType::CubicBSpline, 2.0), 40), 1.0, 1e-3);
}
TEST(Kernel, CubicBSplineIntegratesToOne3D) {
  EXPECT_NEAR(integrateOnLattice(Kernel<3>(KernelType::CubicBSpline, 2.0), 20), 1.0, 1e-3);
}

TEST(Kernel, GradientIsDerivativeOfValue) {
  for (auto type : {KernelType::WendlandC2, KernelType::CubicBSpline}) {
    expectGradientMatchesValue(Kernel<2>(type, 0.7));
    expectGradientMatchesValue(Kernel<3>(type, 0.7));
  }
}

TEST(Kernel, CompactSupportAndSmoothEdge) {
  for (auto type : {KernelType::WendlandC2, KernelType::CubicBSpline}) {
    const Kernel<3> k(type, 1.0);
    EXPECT_EQ(k.value(1.0), 0.0);
    EXPECT_EQ(k.value(1.5), 0.0);
    EXPECT_GT(k.value(0.999), 0.0);
    EXPECT_NEAR(k.derivative(1.0 - 1e-9), 0.0, 1e-6);
    EXPECT_LT(k.derivative(0.5), 0.0);
  }
}

TEST(Kernel, ChapterConstantIsNotNormalised) {
  // docs/method.md section 2: the chapter's 1/(pi h^3) differs from 21/(16 pi h^3) by 21/16.
  const Kernel<3> k(KernelType::WendlandC2, 2.0);  // h = 1
  EXPECT_NEAR(k.value(0.0), 21.0 / (16.0 * std::numbers::pi), 1e-15);
}

TEST(Kernel, RejectsBadInput) {
  EXPECT_THROW(Kernel<2>(KernelType::WendlandC2, 0.0), std::invalid_argument);
  EXPECT_THROW(Kernel<2>(KernelType::WendlandC2, -1.0), std::invalid_argument);
  EXPECT_EQ(parseKernelType("cubic-bspline"), KernelType::CubicBSpline);
  EXPECT_THROW(parseKernelType("gaussian"), std::invalid_argument);
}
