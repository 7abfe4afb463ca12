// Modal analysis (tlsph modes; ModalAnalysis): the zero-energy modes it counts are exactly the
// null space the discretisation has (periodic lattice: spurious zeros without the penalty, only
// the translations with it; free block: the rigid-body motions; clamped beam: none), the
// hourglass content ranks the spurious modes first, and the cantilever's first frequency is
// within 1 % of the Timoshenko beam's at 8 particles through.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>

#include "ProgramRunner.hpp"
#include "TestSupport.hpp"
#include "modes/ModalAnalysis.hpp"
#include "scene/Config.hpp"
#include "scene/SceneBuilder.hpp"

using namespace tlsph;
using namespace tlsph::testing;
namespace fs = std::filesystem;

namespace {

constexpr double kDx = 0.01;

template <int D>
Scene<D> lattice(int cells, bool periodic, double support, double alpha,
                 GradientCorrection correction = GradientCorrection::Linear) {
  std::array<int, D> counts;
  counts.fill(cells);
  Scene<D> scene = sceneOf<D>(cellCentredLattice<D>(Vec<D>::Zero(), counts, kDx), kDx, support,
                              testMaterial("linear-elastic"), alpha);
  scene.gradientCorrection = correction;
  if (periodic) {
    scene.periodicBox.periodic.fill(true);
    scene.periodicBox.length = Vec<D>::Constant(cells * kDx);
  }
  return scene;
}

template <int D>
ModalResult<D> modesOf(Scene<D> scene, int count) {
  Solver<D> solver(scene);
  ModalSettings settings;
  settings.count = count;
  return computeModes(scene, solver, settings);
}

TEST(Modes, PeriodicLatticeZeroModes) {
  // Without the penalty the uncorrected scheme's spurious zeros (as test_zero_energy_modes
  // finds from the full spectrum), with it only the translations.
  const auto without2 = modesOf(lattice<2>(8, true, 2.0, 0.0), 12);
  EXPECT_EQ(without2.zeroModes, 8);
  EXPECT_EQ(without2.expectedRigidModes, 2);
  const auto with2 = modesOf(lattice<2>(8, true, 2.0, 10.0), 12);
  EXPECT_EQ(with2.zeroModes, 2);
  const auto without3 = modesOf(lattice<3>(4, true, 2.0, 0.0), 30);
  EXPECT_EQ(without3.zeroModes, 24);
  EXPECT_EQ(without3.expectedRigidModes, 3);
  const auto with3 = modesOf(lattice<3>(4, true, 2.0, 10.0), 30);
  EXPECT_EQ(with3.zeroModes, 3);
  // the quadratic correction with the penalty on its own F (the scene default)
  EXPECT_EQ(modesOf(lattice<2>(8, true, 2.1, 10.0, GradientCorrection::Quadratic), 12).zeroModes,
            2);
}

TEST(Modes, FreeBlockHasOnlyRigidBodyZeros) {
  for (double alpha : {0.0, 10.0}) {
    const auto r2 = modesOf(lattice<2>(8, false, 2.0, alpha), 8);
    EXPECT_EQ(r2.zeroModes, 3) << "alpha " << alpha;
    EXPECT_EQ(r2.expectedRigidModes, 3);
    const auto r3 = modesOf(lattice<3>(4, false, 2.0, alpha), 10);
    EXPECT_EQ(r3.zeroModes, 6) << "alpha " << alpha;
    EXPECT_EQ(r3.expectedRigidModes, 6);
    // rigid-body modes are smooth: no hourglass content
    for (const auto& m : r3.modes)
      EXPECT_TRUE(!m.zero || m.hourglassContent < 1e-8) << m.hourglassContent;
  }
}

// How much nearest neighbours move together: sum u_I . u_J over sum (|u_I|^2 + |u_J|^2)/2 of
// the pairs of free particles, in [-1, 1]: near 1 for a smooth mode, negative for a zig-zag.
template <int D>
double neighbourCorrelation(const Scene<D>& scene, const std::vector<Vec<D>>& u) {
  const auto& p = scene.particles;
  double together = 0.0, total = 0.0;
  for (Index i = 0; i < p.size(); ++i)
    for (Index j = 0; j < p.size(); ++j)
      if (j != i && p.motion[i] == Motion::Free && p.motion[j] == Motion::Free &&
          (p.referencePosition[i] - p.referencePosition[j]).norm() < 1.01 * kDx) {
        together += u[i].dot(u[j]);
        total += 0.5 * (u[i].squaredNorm() + u[j].squaredNorm());
      }
  return together / total;
}

TEST(Modes, SpuriousModesRankHighestInHourglassContent) {
  // A plane-strain beam 0.2 x 0.04 (20 x 4) held at x = 0 by a prescribed layer, penalty off:
  // the discretisation's zig-zag modes appear among the low ones. The mode of highest
  // hourglass content is a zig-zag (neighbours move against each other); the first bending
  // mode is smooth with almost none. With the penalty on, the zig-zags are lifted above the
  // modes found and the highest content falls.
  auto beam = [](double alpha) {
    std::array<int, 2> counts = {20, 4};
    Scene<2> scene = sceneOf<2>(cellCentredLattice<2>(Vec<2>::Zero(), counts, kDx), kDx, 2.0,
                                testMaterial("linear-elastic"), alpha);
    Prescription<2> held;
    held.name = "held";
    for (Index i = 0; i < scene.particles.size(); ++i)
      if (scene.particles.referencePosition[i].x() < kDx) {
        scene.particles.motion[i] = Motion::Prescribed;
        held.particles.push_back(i);
      }
    scene.prescriptions.push_back(held);
    return scene;
  };
  const Scene<2> off = beam(0.0);
  const auto r = modesOf(off, 24);
  ASSERT_EQ(r.zeroModes, 0);
  std::size_t top = 0;
  for (std::size_t m = 1; m < r.modes.size(); ++m)
    if (r.modes[m].hourglassContent > r.modes[top].hourglassContent) top = m;
  const double topContent = r.modes[top].hourglassContent;
  std::cout << "penalty off: highest hourglass content " << topContent << " (mode " << top + 1
            << ", neighbour correlation " << neighbourCorrelation(off, r.modes[top].shape)
            << "); first mode " << r.modes[0].hourglassContent << " (correlation "
            << neighbourCorrelation(off, r.modes[0].shape) << ")\n";
  EXPECT_LT(neighbourCorrelation(off, r.modes[top].shape), 0.0);
  EXPECT_GT(neighbourCorrelation(off, r.modes[0].shape), 0.9);
  EXPECT_LT(r.modes[0].hourglassContent, 0.01 * topContent);
  const auto lifted = modesOf(beam(10.0), 24);
  double highest = 0.0;
  for (const auto& m : lifted.modes)
    highest = std::max(highest, m.hourglassContent);
  std::cout << "penalty on: highest hourglass content " << highest << "\n";
  EXPECT_LT(highest, 0.5 * topContent);
}

TEST(Modes, ClampedBeamHasNoZeroModes) {
  const std::string text = R"([scene]
dimension = 3
dx = 0.025
[material.rubber]
model = neo-hookean
density = 1000
youngs_modulus = 1.0e7
poisson_ratio = 0.3
[body.beam]
shape = box
lower = 0 -0.05 -0.05
upper = 1.0 0.05 0.05
[clamp.root]
face = x-
[time]
end = 1
)";
  SceneSetup<3> setup = buildScene<3>(Config::parse(text, "beam.ini"));
  const auto r = modesOf(setup.scene, 6);
  EXPECT_EQ(r.zeroModes, 0);
  EXPECT_EQ(r.expectedRigidModes, 0);
  ASSERT_EQ(r.modes.size(), 6u);
  EXPECT_GT(r.modes[0].frequency, 1.0);
  // the first two are the bending pair (square section): equal frequencies
  EXPECT_NEAR(r.modes[1].frequency, r.modes[0].frequency, 1e-6 * r.modes[0].frequency);
}

// The validation's Timoshenko value for examples/cantilever.ini (1 x 0.1 x 0.1 m, E = 1e7 Pa,
// nu = 0.3, rho = 1000, kappa from Cowper): validation/references.py timoshenko_frequency.
constexpr double kTimoshenkoHz = 1.602875336830428;

TEST(Modes, CantileverFirstFrequencyWithinOnePercentOfTimoshenko) {
  SceneSetup<3> setup =
      buildScene<3>(Config::read(fs::path(TLSPH_SOURCE_DIR) / "examples" / "cantilever.ini"));
  const auto r = modesOf(setup.scene, 2);
  ASSERT_EQ(r.modes.size(), 2u);
  const double f = r.modes[0].frequency;
  std::cout << "cantilever at 8 through: first frequency " << f << " Hz, Timoshenko "
            << kTimoshenkoHz << " Hz (" << 100.0 * (f / kTimoshenkoHz - 1.0) << " %)\n";
  EXPECT_NEAR(f, kTimoshenkoHz, 0.01 * kTimoshenkoHz);
}

TEST(Modes, CommandWritesTableAndShapes) {
  const fs::path dir = fs::temp_directory_path() / "tlsph_modes_command";
  fs::remove_all(dir);
  const std::string scene = std::string(TLSPH_SOURCE_DIR) + "/examples/cantilever.ini";
  fs::create_directories(dir);
  const auto r = runProgram(
      "modes " + scene + " --count=3 --scene.dx=0.025 --output.directory=" + dir.string(),
      dir / "log.txt");
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("zero modes   0"), std::string::npos) << r.output;
  EXPECT_TRUE(fs::exists(dir / "modes.csv"));
  EXPECT_TRUE(fs::exists(dir / "cantilever_modes.pvd"));
  EXPECT_TRUE(fs::exists(dir / "cantilever_modes_000002.vtu"));
  const auto bad = runProgram("modes " + scene + " --count=zero", dir / "bad.txt");
  EXPECT_EQ(bad.status, 1);
  EXPECT_NE(bad.output.find("--count expects a whole number"), std::string::npos) << bad.output;
  fs::remove_all(dir);
}

}  // namespace
