// Where the prescribed particles go (PrescribedParticles): the step-end displacement a velocity
// rule integrates is the integral of its velocity, a ramped displacement rule's rate is its
// velocity, a static load time puts each rule where its integral says, and the velocity switch
// is model/Conditions.hpp's one.
#include <gtest/gtest.h>

#include <cmath>

#include "TestSupport.hpp"
#include "explicit/PrescribedMotion.hpp"

using namespace tlsph;
using namespace tlsph::testing;

namespace {

// Four prescribed particles, one per rule of `rules` (in order), plus a free one and a
// prescribed one no rule names; each prescribed particle starts displaced by `u0`.
Scene<2> prescribedScene(const std::vector<Prescription<2>>& rules, const Vec<2>& u0) {
  Scene<2> scene;
  scene.particles.add(Vec<2>(0.0, 0.0), 1.0, 1.0, 0);  // free
  for (std::size_t r = 0; r < rules.size(); ++r) {
    const Index i = scene.particles.add(Vec<2>(0.3 + r, 0.2 * r), 1.0, 1.0, 0, Motion::Prescribed);
    scene.particles.displacement[i] = u0;
    scene.prescriptions.push_back(rules[r]);
    scene.prescriptions.back().particles = {i};
  }
  const Index loose = scene.particles.add(Vec<2>(-1.0, 0.5), 1.0, 1.0, 0, Motion::Prescribed);
  scene.particles.displacement[loose] = u0;
  scene.particles.velocity[loose] = Vec<2>(0.75, -0.5);
  return scene;
}

Prescription<2> rule(PrescribedMotion motion, double ramp) {
  Prescription<2> r;
  r.name = "rule";
  r.motion = motion;
  r.value = Vec<2>(0.3, -0.2);
  r.ramp.duration = ramp;
  r.point = Vec<2>(0.1, -0.4);
  r.rate = 2.0;
  r.axis = -Vec3::UnitZ();
  return r;
}

const std::vector<Prescription<2>> kRules = {
    rule(PrescribedMotion::Fixed, 0.0), rule(PrescribedMotion::Velocity, 0.3),
    rule(PrescribedMotion::Displacement, 0.3), rule(PrescribedMotion::Rotation, 0.3)};

}  // namespace

TEST(PrescribedMotion, SlotsAreThePrescribedParticlesInOrder) {
  const Scene<2> scene = prescribedScene(kRules, Vec<2>::Zero());
  const PrescribedParticles<2> prescribed(scene);
  ASSERT_EQ(prescribed.size(), 5u);
  for (std::size_t k = 0; k < prescribed.size(); ++k) {
    EXPECT_EQ(prescribed.particle(k), Index(k + 1));
    EXPECT_EQ(prescribed.own()[k], k);
  }
}

TEST(PrescribedMotion, APrescriptionNamingAFreeParticleIsASetupError) {
  Scene<2> scene = prescribedScene(kRules, Vec<2>::Zero());
  scene.prescriptions[1].particles.push_back(0);
  EXPECT_THROW(PrescribedParticles<2>{scene}, SetupError);
}

// Stepping each rule through the step-end displacements (the explicit solver's way) lands
// where the static displacement (its exact integral) says, and the velocity is the rate of
// that displacement. The velocity rule's midpoint integration is exact except over the step
// that holds the ramp's kink.
TEST(PrescribedMotion, StepEndDisplacementIntegratesTheVelocityRule) {
  const Vec<2> u0(0.01, -0.02);
  Scene<2> scene = prescribedScene(kRules, u0);
  const PrescribedParticles<2> prescribed(scene);
  const double dt = 7e-3;
  const int steps = 100;  // past the ramp (0.3)
  auto& p = scene.particles;
  for (int s = 1; s <= steps; ++s) {
    const double t = s * dt;
    std::vector<Vec<2>> next(prescribed.size());
    for (std::size_t k = 0; k < prescribed.size(); ++k)
      next[k] = prescribed.displacementAtStepEnd(k, t, dt);
    for (std::size_t k = 0; k < prescribed.size(); ++k) {
      p.displacement[prescribed.particle(k)] = next[k];
      p.velocity[prescribed.particle(k)] = prescribed.velocity(k, t);
    }
  }
  const double T = steps * dt;
  for (std::size_t k = 0; k < 4; ++k) {
    const Vec<2> exact = prescribed.staticDisplacement(k, T);
    // A kink of the ramp inside a step: error at most |value| dt^2 / (8 ramp) of the
    // midpoint rule on that step.
    const double tolerance = k == 1 ? 1.01 * 0.3606 * dt * dt / (8 * 0.3) : 1e-14;
    EXPECT_LT((p.displacement[prescribed.particle(k)] - exact).norm(), tolerance) << "rule " << k;
  }
  // The velocity rule moved: its integral from 0 is value (T - ramp / 2).
  EXPECT_LT((prescribed.staticDisplacement(1, T) - (u0 + Vec<2>(0.3, -0.2) * (T - 0.15))).norm(),
            1e-14);
  // The unnamed particle kept its velocity: moved by v T from where it started.
  const Index loose = prescribed.particle(4);
  EXPECT_LT((p.displacement[loose] - (u0 + T * Vec<2>(0.75, -0.5))).norm(), 1e-12);
  EXPECT_EQ(prescribed.staticDisplacement(4, T), u0);
}

// The velocity of every rule is the time derivative of its static displacement, during the
// ramp and after it (central differences, whose error is O(h^2)).
TEST(PrescribedMotion, VelocityIsTheRateOfTheStaticDisplacement) {
  const Vec<2> u0(0.01, -0.02);
  Scene<2> scene = prescribedScene(kRules, u0);
  const PrescribedParticles<2> prescribed(scene);
  const double h = 1e-6;
  for (double t : {0.1, 0.2, 0.5, 1.7})
    for (std::size_t k = 0; k < 4; ++k) {
      const Index i = prescribed.particle(k);
      scene.particles.displacement[i] = prescribed.staticDisplacement(k, t);
      const Vec<2> rate =
          (prescribed.staticDisplacement(k, t + h) - prescribed.staticDisplacement(k, t - h)) /
          (2 * h);
      EXPECT_LT((prescribed.velocity(k, t) - rate).norm(), 1e-8) << "rule " << k << " t " << t;
    }
}

// Ramped rules start where the particles are, the velocity and rotation rules from rest (a
// ramped displacement starts at its full rate).
TEST(PrescribedMotion, RampsStartFromRestAndHoldAfterwards) {
  const Scene<2> scene = prescribedScene(kRules, Vec<2>::Zero());
  const PrescribedParticles<2> prescribed(scene);
  for (std::size_t k = 0; k < 4; ++k)
    EXPECT_LT(prescribed.staticDisplacement(k, 0.0).norm(), 1e-15) << k;  // a rotation rounds
  for (std::size_t k : {0, 1, 3})
    EXPECT_EQ(prescribed.velocity(k, 0.0), Vec<2>::Zero()) << k;
  EXPECT_LT((prescribed.velocity(2, 0.1) - Vec<2>(0.3, -0.2) / 0.3).norm(), 1e-15);
  // After the ramp: the velocity rule at its full value, the displacement rule held still.
  EXPECT_EQ(prescribed.velocity(1, 0.5), Vec<2>(0.3, -0.2));
  EXPECT_EQ(prescribed.velocity(2, 0.5), Vec<2>::Zero());
  EXPECT_EQ(prescribed.staticDisplacement(2, 0.5), Vec<2>(0.3, -0.2));
  EXPECT_EQ(prescribed.staticDisplacement(2, 0.15), Vec<2>(0.15, -0.1));
  EXPECT_EQ(prescribed.displacementAtStepEnd(2, 0.15, 0.01), Vec<2>(0.15, -0.1));
}

// A rotation keeps each particle's distance to the centre and follows it exactly at any time,
// from wherever the particle started.
TEST(PrescribedMotion, RotationIsExactFromTheStartingPosition) {
  const Vec<2> u0(0.01, -0.02);
  const Scene<2> scene = prescribedScene(kRules, u0);
  const PrescribedParticles<2> prescribed(scene);
  const Index i = prescribed.particle(3);
  const Vec<2> X = scene.particles.referencePosition[i], c = kRules[3].point;
  for (double t : {0.05, 0.3, 2.0}) {
    const double angle = t < 0.3 ? 2.0 * t * t / 0.6 : 2.0 * (t - 0.15);
    const Eigen::Rotation2Dd R(-angle);  // about -z
    const Vec<2> expected = c + R * (X + u0 - c) - X;
    EXPECT_LT((prescribed.staticDisplacement(3, t) - expected).norm(), 1e-13) << t;
    EXPECT_LT((prescribed.displacementAtStepEnd(3, t, 0.01) - expected).norm(), 1e-13) << t;
  }
}

// The solver's prescribed particles and the mirrored faces share Conditions.hpp's velocity
// switch: at a face point's prescribed position it is the face's velocity.
TEST(PrescribedMotion, FaceVelocityIsTheSharedSwitchAtThePrescribedPosition) {
  for (const auto& r : kRules)
    for (double t : {0.1, 0.7}) {
      const Vec<2> X(0.4, -0.3);
      const Vec<2> x = X + prescribedDisplacementAt(r, X, t);
      EXPECT_LT((prescribedVelocityAt(r, X, t) - prescribedVelocityAtPosition(r, x, t)).norm(),
                1e-15);
    }
}
