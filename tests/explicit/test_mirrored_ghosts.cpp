// The mirrored clamp (docs/method.md section 3): ghosts take the odd reflection u_ghost = -u_mirror
// of the body particle mirrored across the face, carry no strain energy, and send their force back
// to the mirror particle. Then the force on the body is -dE/du of the body's energy (strain plus
// hourglass), an undamped run keeps its energy books balanced, and a field that vanishes on the
// face with odd symmetry is reproduced exactly by the ghosts. Then MirroredGhosts piece by
// piece: the checks of the ghost list, the extrapolation, the drive of a moving face, the
// chain rule and the reaction's ghost part.
#include <gtest/gtest.h>

#include "TestSupport.hpp"
#include "explicit/MirroredGhosts.hpp"
#include "explicit/Solver.hpp"

using namespace tlsph;
using namespace tlsph::testing;

namespace {

constexpr double kDx = 0.01;

enum class Extrapolation { Odd, Quadratic };

// A 2D beam 0.16 x 0.04 m (16 x 4 particles) or a 3D one 0.08 x 0.03 x 0.03 (8 x 3 x 3),
// clamped at x = 0 by three mirrored ghost layers: the odd reflection u_g = -u_1 (method =
// mirror) or the quadratic extrapolation through the face and body layers k, k + 1 (method =
// mirror-quadratic: w1 = -2k, w2 = (2k - 1)^2 / (2k + 1)). With a rule, the face follows it
// (the rule is the scene's prescription 0).
template <int D>
Scene<D> mirroredBeam(double alpha, GradientCorrection correction,
                      Extrapolation extrapolation = Extrapolation::Odd,
                      const Prescription<D>* rule = nullptr) {
  std::array<int, D> counts;
  counts.fill(D == 2 ? 4 : 3);
  counts[0] = D == 2 ? 16 : 8;
  const auto X = cellCentredLattice<D>(Vec<D>::Zero(), counts, kDx);
  Scene<D> scene = sceneOf<D>(X, kDx, 2.5, testMaterial("neo-hookean"), alpha);
  scene.gradientCorrection = correction;
  if (rule) scene.prescriptions.push_back(*rule);
  const double V = std::pow(kDx, D);
  const Index body = scene.particles.size();
  auto next = [&](Index i) {  // the body particle one layer further in
    const Vec<D> Y = scene.particles.referencePosition[i] + kDx * Vec<D>::UnitX();
    for (Index j = 0; j < body; ++j)
      if ((scene.particles.referencePosition[j] - Y).norm() < 1e-9) return j;
    return Index(-1);
  };
  for (Index i = 0; i < body; ++i) {
    const Vec<D> Xi = scene.particles.referencePosition[i];
    const int layer = static_cast<int>(std::lround(Xi.x() / kDx - 0.5));  // 0, 1, 2, ...
    if (layer >= 3) continue;
    Vec<D> G = Xi;
    G.x() = -Xi.x();  // ghost layer k mirrors body layer k
    const Index g = scene.particles.add(G, V, 1000.0 * V, 0, Motion::Mirrored);
    MirrorGhost m;
    m.ghost = g;
    m.mirror = i;
    if (extrapolation == Extrapolation::Quadratic) {
      const double k = layer + 1;
      m.second = next(i);
      m.w1 = -2.0 * k;
      m.w2 = (2.0 * k - 1.0) * (2.0 * k - 1.0) / (2.0 * k + 1.0);
    }
    m.motion = rule ? 0 : -1;
    scene.mirrorGhosts.push_back(m);
  }
  return scene;
}

template <int D>
void expectForceIsMinusBodyEnergyGradient(GradientCorrection correction, std::uint32_t seed,
                                          Extrapolation extrapolation = Extrapolation::Odd) {
  std::mt19937 rng(seed);
  const Scene<D> base = mirroredBeam<D>(10.0, correction, extrapolation);
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
      worst = worseOf(worst, std::abs(-(plus - minus) / (2 * h) - f[i][a]));
    }
  EXPECT_LT(worst, 1e-6 * fmax) << D << "D";
}

struct Books {
  double error = 0.0;  // max |E_total(t) - E_total(0)| / peak strain energy
  double peakStrain = 0.0;
  double boundaryWork = 0.0;  // at the end
};

template <int D>
Books undampedVibration(double cfl, int steps, Extrapolation extrapolation = Extrapolation::Odd,
                        const Prescription<D>* rule = nullptr) {
  Scene<D> scene = mirroredBeam<D>(10.0, GradientCorrection::Quadratic, extrapolation, rule);
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
      b.boundaryWork = e.boundaryWork;
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
  expectForceIsMinusBodyEnergyGradient<2>(GradientCorrection::Quadratic, 64,
                                          Extrapolation::Quadratic);
  expectForceIsMinusBodyEnergyGradient<3>(GradientCorrection::Quadratic, 65,
                                          Extrapolation::Quadratic);
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

namespace {

// Sets the body to `field`, then: the largest error of the ghosts' displacements against the
// field at their positions, and of F - 1 against `gradient` at the body particles within 3 dx
// of the face (the beam's free top and bottom are included; the face is what counts).
template <class Field, class Gradient>
std::pair<double, double> reproductionErrors(Scene<2> scene, Field field, Gradient gradient) {
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
    worstF = std::max(worstF, (F[i] - Mat<2>::Identity() - gradient(X)).norm());
  }
  return {worstGhost, worstF};
}

}  // namespace

// u_x = a x + b x y, u_y = c x (vanishing on x = 0, odd in x): the ghosts' values are the
// field's own at their positions, so every body particle next to the face sees the exact field
// and its F is exact (quadratic correction).
TEST(MirroredClamp, ReproducesAnOddFieldThatVanishesOnTheFace) {
  const auto [ghost, F] = reproductionErrors(
      mirroredBeam<2>(0.0, GradientCorrection::Quadratic),
      [](const Vec<2>& X) { return Vec<2>(0.02 * X.x() + 3.0 * X.x() * X.y(), -0.05 * X.x()); },
      [](const Vec<2>& X) {
        Mat<2> G;
        G << 0.02 + 3.0 * X.y(), 3.0 * X.x(), -0.05, 0.0;
        return G;
      });
  EXPECT_LT(ghost, 1e-15);
  EXPECT_LT(F, 1e-10);
}

// The extrapolation of method = mirror-quadratic is exact for every quadratic field that
// vanishes on the face, even ones (x^2) included: the ghosts take the field's own values, and F
// is exact at the particles next to the face.
TEST(MirroredClamp, QuadraticExtrapolationReproducesAQuadraticFieldThatVanishesOnTheFace) {
  const auto [ghost, F] = reproductionErrors(
      mirroredBeam<2>(0.0, GradientCorrection::Quadratic, Extrapolation::Quadratic),
      [](const Vec<2>& X) {
        return Vec<2>(0.02 * X.x() + 3.0 * X.x() * X.x() + 2.0 * X.x() * X.y(),
                      -0.05 * X.x() + 4.0 * X.x() * X.x());
      },
      [](const Vec<2>& X) {
        Mat<2> G;
        G << 0.02 + 6.0 * X.x() + 2.0 * X.y(), 2.0 * X.x(), -0.05 + 8.0 * X.x(), 0.0;
        return G;
      });
  EXPECT_LT(ghost, 1e-15);
  EXPECT_LT(F, 1e-10);
}

// A moving face: the ghosts follow the prescribed motion u_p plus the extrapolated deviation of
// the body from it. A body in the same rigid motion (translation, rotation) plus a field that
// vanishes on the face is reproduced at the ghosts exactly, and a rigid motion alone leaves no
// force.
TEST(MirroredClamp, MovingFaceGhostsFollowThePrescribedMotion) {
  for (const auto extrapolation : {Extrapolation::Odd, Extrapolation::Quadratic}) {
    for (const auto motion : {PrescribedMotion::Displacement, PrescribedMotion::Rotation}) {
      Prescription<2> rule;
      rule.name = "clamp.root";
      rule.motion = motion;
      rule.value = Vec<2>(0.003, -0.002);
      rule.point = Vec<2>(0.0, 0.02);
      rule.rate = 0.4;
      rule.ramp.duration = 0.0;
      Scene<2> scene = mirroredBeam<2>(10.0, GradientCorrection::Quadratic, extrapolation, &rule);
      // At t = 0 (no ramp) the displacement rule has moved the face by `value`; the rotation
      // has not turned yet but its velocities are non-zero, which the ghosts must follow.
      const auto up = [&](const Vec<2>& X) { return prescribedDisplacementAt(rule, X, 0.0); };
      const auto vp = [&](const Vec<2>& X) { return prescribedVelocityAt(rule, X, 0.0); };
      auto q = [&](const Vec<2>& X) {  // vanishes on x = 0; odd in x for the odd reflection
        const double even = extrapolation == Extrapolation::Quadratic ? 2.0 * X.x() * X.x() : 0.0;
        return Vec<2>(0.01 * X.x() + 3.0 * X.x() * X.y() + even, -0.04 * X.x());
      };
      for (Index i = 0; i < scene.particles.size(); ++i)
        if (scene.particles.motion[i] == Motion::Free) {
          const Vec<2> X = scene.particles.referencePosition[i];
          scene.particles.displacement[i] = up(X) + q(X);
          scene.particles.velocity[i] = vp(X) + 0.5 * q(X);
        }
      Solver<2> solver(scene);
      double worstU = 0.0, worstV = 0.0;
      for (const auto& m : scene.mirrorGhosts) {
        const Vec<2> G = scene.particles.referencePosition[m.ghost];
        worstU = std::max(worstU, (scene.particles.displacement[m.ghost] - up(G) - q(G)).norm());
        worstV = std::max(worstV, (scene.particles.velocity[m.ghost] - vp(G) - 0.5 * q(G)).norm());
      }
      EXPECT_LT(worstU, 1e-15);
      EXPECT_LT(worstV, 1e-14);
    }
  }
  // Rigid translation of body and face: no force anywhere.
  Prescription<3> rule;
  rule.name = "clamp.root";
  rule.motion = PrescribedMotion::Displacement;
  rule.value = Vec<3>(0.002, -0.001, 0.003);
  Scene<3> scene = mirroredBeam<3>(10.0, GradientCorrection::Quadratic, Extrapolation::Odd, &rule);
  for (Index i = 0; i < scene.particles.size(); ++i)
    if (scene.particles.motion[i] == Motion::Free) scene.particles.displacement[i] = rule.value;
  Solver<3> solver(scene);
  double fmax = 0.0;
  for (Index i = 0; i < scene.particles.size(); ++i)
    fmax = std::max(fmax, scene.particles.force[i].norm());
  EXPECT_LT(fmax, 1e-9);
}

// The reaction of a clamp is the net force the body receives through it: with no loads the
// chained internal forces of the body sum to the clamp's reaction (fixed ghosts and both
// mirrored extrapolations), for any displacement.
TEST(MirroredClamp, ReactionIsTheNetForceOnTheBody) {
  std::mt19937 rng(71);
  for (int method = 0; method < 3; ++method) {
    Prescription<3> rule;
    rule.name = "clamp.root";
    Scene<3> scene =
        mirroredBeam<3>(10.0, GradientCorrection::Quadratic,
                        method == 1 ? Extrapolation::Quadratic : Extrapolation::Odd, &rule);
    if (method == 2) {  // the chapter's fixed ghosts: prescribed particles of the rule
      for (const auto& m : scene.mirrorGhosts) {
        scene.particles.motion[m.ghost] = Motion::Prescribed;
        scene.prescriptions[0].particles.push_back(m.ghost);
      }
      scene.mirrorGhosts.clear();
    }
    const Mat<3> A = randomMatrix<3>(rng, 0.05);
    for (Index i = 0; i < scene.particles.size(); ++i)
      if (scene.particles.motion[i] == Motion::Free)
        scene.particles.displacement[i] =
            A * scene.particles.referencePosition[i] + randomVector<3>(rng, 0.03 * kDx);
    Solver<3> solver(scene);
    Vec<3> net = Vec<3>::Zero();
    double scale = 0.0;
    for (Index i = 0; i < scene.particles.size(); ++i)
      if (scene.particles.motion[i] == Motion::Free) {
        net += scene.particles.force[i];
        scale = std::max(scale, scene.particles.force[i].norm());
      }
    EXPECT_GT(net.norm(), 1e-3 * scale) << method;  // the test means something
    EXPECT_LT((solver.reaction(0) - net).norm(), 1e-12 * scale) << method;
  }
}

// A face that moves (rotation, both extrapolations) keeps the energy books: the work the face
// does, booked as boundary work, is what the body gains.
TEST(MirroredClamp, MovingFaceKeepsTheEnergyBooks) {
  for (const auto extrapolation : {Extrapolation::Odd, Extrapolation::Quadratic}) {
    Prescription<2> rule;
    rule.name = "clamp.root";
    rule.motion = PrescribedMotion::Rotation;
    rule.point = Vec<2>(0.0, 0.02);
    rule.rate = 5.0;
    rule.ramp.duration = 0.01;
    const Books b = undampedVibration<2>(kDefaultCfl, 3000, extrapolation, &rule);
    const Books half = undampedVibration<2>(0.5 * kDefaultCfl, 3000, extrapolation, &rule);
    std::cout << "moving mirrored face: energy-balance error " << b.error
              << " of the peak strain energy (" << half.error << " at dt/2), boundary work "
              << b.boundaryWork << " J\n";
    EXPECT_GT(b.boundaryWork, 0.1 * b.peakStrain);
    EXPECT_LT(b.error, 1e-3);
    EXPECT_LT(half.error, b.error / 3.0);
  }
}

namespace {

// A line of particles along x: ghost g at -0.5 mirrors body particle 1 at 0.5 across the face
// x = 0, with particle 2 at 1.5 the next one inward (quadratic extrapolation weights), and a
// second ghost at -1.5 that follows particle 2 only (odd reflection). The face follows
// prescription 0 when `moving`.
Scene<2> ghostLine(bool moving) {
  Scene<2> scene;
  auto& p = scene.particles;
  p.add(Vec<2>(0.5, 0.0), 1.0, 1.0, 0);                     // 0: mirror particle 1
  p.add(Vec<2>(1.5, 0.0), 1.0, 1.0, 0);                     // 1: particle 2
  p.add(Vec<2>(-0.5, 0.0), 1.0, 1.0, 0, Motion::Mirrored);  // 2: ghost of 0 (and 1)
  p.add(Vec<2>(-1.5, 0.0), 1.0, 1.0, 0, Motion::Mirrored);  // 3: ghost of 1
  Prescription<2> face;
  face.name = "face";
  face.motion = PrescribedMotion::Velocity;
  face.value = Vec<2>(0.0, 0.2);
  face.ramp.duration = 1.0;
  scene.prescriptions.push_back(face);
  MirrorGhost a;
  a.ghost = 2;
  a.mirror = 0;
  a.w1 = -2.0;
  a.second = 1;
  a.w2 = 1.0 / 3.0;
  a.motion = moving ? 0 : -1;
  MirrorGhost b;
  b.ghost = 3;
  b.mirror = 1;
  b.motion = moving ? 0 : -1;
  scene.mirrorGhosts = {a, b};
  p.displacement[0] = Vec<2>(0.01, 0.02);
  p.displacement[1] = Vec<2>(-0.03, 0.05);
  p.velocity[0] = Vec<2>(1.0, -2.0);
  p.velocity[1] = Vec<2>(0.5, 0.25);
  return scene;
}

}  // namespace

TEST(MirroredGhosts, GhostListIsChecked) {
  EXPECT_EQ(MirroredGhosts<2>::checkedGhostList(ghostLine(false)), (std::vector<Index>{2, 3}));
  Scene<2> orphan = ghostLine(false);
  orphan.mirrorGhosts.pop_back();  // particle 3 is mirrored with no mirror
  EXPECT_THROW(MirroredGhosts<2>::checkedGhostList(orphan), SetupError);
  Scene<2> ghostOfGhost = ghostLine(false);
  ghostOfGhost.mirrorGhosts[1].mirror = 2;  // follows a ghost, not a free particle
  EXPECT_THROW(MirroredGhosts<2>::checkedGhostList(ghostOfGhost), SetupError);
  Scene<2> noRule = ghostLine(true);
  noRule.mirrorGhosts[0].motion = 1;  // there is one prescription only
  EXPECT_THROW(MirroredGhosts<2>::checkedGhostList(noRule), SetupError);
}

// A fixed face: the ghosts are the weighted sums of the body particles they follow, in
// displacement and in velocity; no drive.
TEST(MirroredGhosts, FixedFaceGhostsExtrapolateTheBody) {
  Scene<2> scene = ghostLine(false);
  const MirroredGhosts<2> ghosts(scene);
  EXPECT_FALSE(ghosts.moving());
  auto& p = scene.particles;
  ghosts.move(p);
  EXPECT_LT((p.displacement[2] - (-2.0 * p.displacement[0] + p.displacement[1] / 3.0)).norm(),
            1e-16);
  EXPECT_LT((p.velocity[2] - (-2.0 * p.velocity[0] + p.velocity[1] / 3.0)).norm(), 1e-15);
  EXPECT_EQ(p.displacement[3], -p.displacement[1]);
  EXPECT_EQ(p.velocity[3], -p.velocity[1]);
}

// A moving face: each ghost adds the drive d_g = u_p(X_g) - w1 u_p(X_1) - w2 u_p(X_2), so a
// body in the face's own motion is extended exactly; the drive's change over a step is what
// the face's work is booked on.
TEST(MirroredGhosts, MovingFaceDrivesTheGhosts) {
  Scene<2> scene = ghostLine(true);
  MirroredGhosts<2> ghosts(scene);
  EXPECT_TRUE(ghosts.moving());
  auto& p = scene.particles;
  const auto& rule = scene.prescriptions[0];
  const double t = 0.4;
  ghosts.updateDrive(t);
  for (Index i : {0, 1}) {  // the body in the face's motion
    p.displacement[i] = prescribedDisplacementAt(rule, p.referencePosition[i], t);
    p.velocity[i] = prescribedVelocityAt(rule, p.referencePosition[i], t);
  }
  ghosts.move(p);
  for (Index g : {2, 3}) {
    EXPECT_LT(
        (p.displacement[g] - prescribedDisplacementAt(rule, p.referencePosition[g], t)).norm(),
        1e-15)
        << g;
    EXPECT_LT((p.velocity[g] - prescribedVelocityAt(rule, p.referencePosition[g], t)).norm(), 1e-15)
        << g;
  }
  // A translation: u_p is the same everywhere, so d = (1 - w1 - w2) u_p.
  const auto before = ghosts.drive();
  const auto change = ghosts.advanceDrive(0.6);
  ASSERT_EQ(change.size(), 2u);
  const Vec<2> du = prescribedDisplacementAt<2>(rule, Vec<2>::Zero(), 0.6) -
                    prescribedDisplacementAt<2>(rule, Vec<2>::Zero(), t);
  EXPECT_LT((change[0] - (1.0 + 2.0 - 1.0 / 3.0) * du).norm(), 1e-15);
  EXPECT_LT((change[1] - 2.0 * du).norm(), 1e-15);
  EXPECT_LT((ghosts.drive()[1] - before[1] - change[1]).norm(), 1e-17);
  // A static state holds the faces still.
  ghosts.holdDriveAt(0.6);
  ghosts.move(p);
  EXPECT_LT((p.velocity[3] + p.velocity[1]).norm(), 1e-15);
  // A fixed face has no drive to change.
  const Scene<2> still = ghostLine(false);
  MirroredGhosts<2> fixed(still);
  EXPECT_TRUE(fixed.advanceDrive(0.6).empty());
}

// The chain rule sends w1 and w2 of each ghost's force to the particles it follows; the rest,
// (1 - w1 - w2) f_ghost, is what the face takes: the reaction's ghost part, so that body and
// reaction together hold the ghost's whole force.
TEST(MirroredGhosts, ChainRuleAndReactionShareTheGhostForce) {
  Scene<2> scene = ghostLine(true);
  const MirroredGhosts<2> ghosts(scene);
  std::vector<Vec<2>> f = {Vec<2>(1.0, 2.0), Vec<2>(-3.0, 0.5), Vec<2>(0.25, -1.0),
                           Vec<2>(4.0, 3.0)};
  const std::vector<Vec<2>> before = f;
  ghosts.chainForces(f);
  EXPECT_EQ(f[0], before[0] - 2.0 * before[2]);
  EXPECT_LT((f[1] - (before[1] + before[2] / 3.0 - before[3])).norm(), 1e-15);
  EXPECT_EQ(f[2], before[2]);  // the ghost keeps its own force
  Vec<2> R = Vec<2>::Zero();
  ghosts.addReaction(0, f, R);
  const Vec<2> body = (f[0] - before[0]) + (f[1] - before[1]);
  EXPECT_LT((body - R - (before[2] + before[3])).norm(), 1e-14);
  Vec<2> none = Vec<2>::Zero();
  ghosts.addReaction(1, f, none);
  EXPECT_EQ(none, Vec<2>::Zero());
}

TEST(MirroredGhosts, ARankKeepsTheGhostsOfItsParticles) {
  Scene<2> scene = ghostLine(false);
  MirroredGhosts<2> ghosts(scene);
  EXPECT_EQ(ghosts.own(), (std::vector<std::size_t>{0, 1}));
  ghosts.keepOwn({1, 1, 0, 1});
  EXPECT_EQ(ghosts.own(), (std::vector<std::size_t>{1}));
  std::vector<Vec<2>> f(4, Vec<2>(1.0, 1.0));
  ghosts.chainForces(f);
  EXPECT_EQ(f[0], Vec<2>(1.0, 1.0));  // ghost 0 is another rank's
  EXPECT_EQ(f[1], Vec<2>(0.0, 0.0));
}
