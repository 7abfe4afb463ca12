// The explicit stable time step (method/TimeStep.hpp): dt = C min_I dx_I / c_eff,I with
// dx_I = V_I^(1/d) (or the neighbourhood spacing given), c_eff^2 = c^2 + kappa dx^2 K_I / m_I,
// kappa = 1/16; the particle that sets it is reported; only free particles count when there are
// any; candidates restrict the set.
#include <gtest/gtest.h>

#include <cmath>

#include "materials/Material.hpp"
#include "method/TimeStep.hpp"

using namespace tlsph;

namespace {

// c = sqrt((lambda + 2 mu) / rho) from E and nu directly.
double pWaveSpeed(double E, double nu, double rho) {
  const double lambda = E * nu / ((1 + nu) * (1 - 2 * nu)), mu = E / (2 * (1 + nu));
  return std::sqrt((lambda + 2 * mu) / rho);
}

struct ThreeParticles {
  std::vector<Material> materials{
      makeMaterial("neo-hookean", ElasticConstants::fromYoungPoisson(2.0e6, 0.3), 1000.0),
      makeMaterial("linear-elastic", ElasticConstants::fromYoungPoisson(8.0e6, 0.25), 2000.0)};
  ParticleSet<2> particles;
  ThreeParticles() {
    particles.add(Vec<2>(0, 0), 1e-4, 0.1, 0);       // dx 0.01, c 51.89 m/s
    particles.add(Vec<2>(1, 0), 0.64e-4, 0.128, 1);  // dx 0.008, c 69.28 m/s
    particles.add(Vec<2>(2, 0), 0.25e-4, 0.025, 0);  // dx 0.005
  }
};

}  // namespace

TEST(TimeStep, WaveSpeedRule) {
  ThreeParticles p;
  const double c0 = pWaveSpeed(2.0e6, 0.3, 1000.0);
  EXPECT_NEAR(c0, 51.887452, 1e-6);
  EXPECT_NEAR(waveSpeed(p.materials[1]), pWaveSpeed(8.0e6, 0.25, 2000.0), 1e-12);
  const StableStep s = stableStep(p.particles, p.materials, 0.3);
  EXPECT_EQ(s.particle, 2);
  EXPECT_NEAR(s.dx, 0.005, 1e-15);
  EXPECT_NEAR(s.waveSpeed, c0, 1e-12);
  EXPECT_NEAR(s.dt, 0.3 * 0.005 / c0, 1e-15);
  EXPECT_EQ(s.hourglassSpeed, 0.0);
  EXPECT_EQ(s.hourglassFactor(), 1.0);
  EXPECT_EQ(stableTimeStep(p.particles, p.materials, 0.3), s.dt);
  EXPECT_EQ(kDefaultCfl, 0.3);
}

TEST(TimeStep, HourglassStiffnessRaisesTheSpeed) {
  ThreeParticles p;
  const double c1 = pWaveSpeed(8.0e6, 0.25, 2000.0);
  // a stiff penalty on particle 1 only: c_hg^2 = dx^2 K / (16 m)
  const std::vector<double> K = {0.0, 1.0e9, 0.0};
  const double chg = std::sqrt(0.008 * 0.008 * 1.0e9 / (16.0 * 0.128));
  EXPECT_EQ(kHourglassSpeedFactor, 1.0 / 16.0);
  const StableStep s = stableStep(p.particles, p.materials, 0.5, K);
  ASSERT_LT(0.008 / std::hypot(c1, chg), 0.005 / pWaveSpeed(2.0e6, 0.3, 1000.0));
  EXPECT_EQ(s.particle, 1);
  EXPECT_NEAR(s.hourglassSpeed, chg, 1e-12 * chg);
  EXPECT_NEAR(s.dt, 0.5 * 0.008 / std::hypot(c1, chg), 1e-15);
  EXPECT_NEAR(s.hourglassFactor(), std::hypot(c1, chg) / c1, 1e-12);
}

TEST(TimeStep, OnlyFreeParticlesAndCandidatesCount) {
  ThreeParticles p;
  p.particles.motion[2] = Motion::Prescribed;
  EXPECT_EQ(stableStep(p.particles, p.materials, 0.3).particle, 1);  // 0.008 / 69 < 0.01 / 52
  const std::vector<Index> candidates = {0};
  EXPECT_EQ(stableStep(p.particles, p.materials, 0.3, {}, &candidates).particle, 0);
  // with no free particle at all, every particle counts
  for (auto& m : p.particles.motion)
    m = Motion::Prescribed;
  EXPECT_EQ(stableStep(p.particles, p.materials, 0.3).particle, 2);
}

// dx_I is the spacing of I's neighbourhood: equal volumes give V^(1/d) exactly; a small cell
// among normal ones takes its neighbours' mean, so it does not set the step.
TEST(TimeStep, NeighbourhoodSpacingIgnoresOneSmallCell) {
  NeighbourList nb;
  nb.offset = {0, 2, 4, 6};
  nb.neighbour = {1, 2, 0, 2, 0, 1};
  const std::vector<double> equal = {0.3e-4, 0.3e-4, 0.3e-4};
  for (double dx : neighbourhoodSpacing<2>(nb, equal))
    EXPECT_EQ(dx, std::sqrt(0.3e-4));
  ThreeParticles p;
  p.particles.volume = {1e-4, 1e-4, 0.01e-4};  // particle 2: a cell of 0.1 dx
  const std::vector<double> dx = neighbourhoodSpacing<2>(nb, p.particles.volume);
  EXPECT_NEAR(dx[2], std::sqrt(2.01e-4 / 3.0), 1e-15);
  const StableStep s = stableStep(p.particles, p.materials, 0.3, {}, nullptr, dx);
  EXPECT_EQ(s.dx, dx[s.particle]);
  EXPECT_EQ(s.particle, 1);  // the same spacing everywhere: the faster material sets it
  EXPECT_NEAR(s.dt, 0.3 * dx[1] / pWaveSpeed(8.0e6, 0.25, 2000.0), 1e-15);
  // without a list a particle keeps its own cell
  nb.offset = {0, 2, 4, 4};
  nb.neighbour = {1, 2, 0, 2};
  EXPECT_EQ(neighbourhoodSpacing<2>(nb, p.particles.volume)[2], std::sqrt(0.01e-4));
}
