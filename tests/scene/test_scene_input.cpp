// Bad scene input gets a clear error naming the file, the section, the key and what was
// expected; good input builds the scene it describes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <random>
#include <sstream>
#include <string>

#include "scene/Config.hpp"
#include "scene/InputError.hpp"
#include "scene/SceneBuilder.hpp"

using namespace tlsph;

namespace {

const std::string kGood = R"(
[scene]
dimension = 2
dx = 0.01
[material.steel]
model = neo-hookean
density = 1000
youngs_modulus = 1e6
poisson_ratio = 0.3
[body.bar]
shape = box
lower = 0 0
upper = 0.2 0.04
[clamp.root]
face = x-
[region.tip]
shape = box
lower = 0.19 0
upper = 0.2 0.04
[load.pull]
region = tip
type = force
value = 10 0
[time]
end = 0.01
)";

// The error message of building `text` with the overrides, or "" if it builds.
std::string errorOf(const std::string& text, const std::vector<std::string>& overrides = {}) {
  try {
    const Config config = Config::parse(text, "scene.ini", overrides);
    if (sceneDimension(config) == 2)
      buildScene<2>(config);
    else
      buildScene<3>(config);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

void expectError(const std::string& message, std::initializer_list<std::string> parts) {
  ASSERT_FALSE(message.empty()) << "expected an error";
  for (const auto& part : parts)
    EXPECT_NE(message.find(part), std::string::npos) << message;
}

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return text.replace(at, from.size(), to);
}

}  // namespace

TEST(SceneInput, GoodSceneBuilds) {
  EXPECT_EQ(errorOf(kGood), "");
  const SceneSetup<2> setup = buildScene<2>(Config::parse(kGood, "scene.ini"));
  // 20 x 4 body particles plus ceil(2.1) = 3 ghost columns of 4.
  EXPECT_EQ(setup.scene.particles.size(), 80 + 12);
  EXPECT_EQ(setup.regions.at("tip").size(), 4u);
  ASSERT_EQ(setup.scene.loads.size(), 1u);
  Vec<2> total = Vec<2>::Zero();
  for (const auto& f : setup.scene.loads[0].force)
    total += f;
  EXPECT_NEAR(total.x(), 10.0, 1e-12);  // a total force is shared out exactly
}

TEST(SceneInput, UnknownKeyWithSuggestion) {
  expectError(errorOf(replaced(kGood, "poisson_ratio", "poison_ratio")),
              {"scene.ini:9", "[material.steel]", "poison_ratio", "did you mean 'poisson_ratio'"});
}

TEST(SceneInput, UnknownSection) {
  expectError(errorOf(kGood + "[tmie]\nend = 1\n"), {"[tmie]", "unknown section", "[time]"});
}

TEST(SceneInput, MissingRequiredKey) {
  expectError(errorOf(replaced(kGood, "density = 1000", "")),
              {"[material.steel]", "density", "missing required key"});
  expectError(errorOf(replaced(kGood, "end = 0.01", "")), {"[time]", "end", "missing"});
}

TEST(SceneInput, MalformedVector) {
  expectError(errorOf(replaced(kGood, "upper = 0.2 0.04", "upper = 0.2 0.04 0.1")),
              {"[body.bar]", "upper", "expected 2 numbers"});
  expectError(errorOf(replaced(kGood, "value = 10 0", "value = 10 zero")),
              {"[load.pull]", "value", "expected a number", "zero"});
}

TEST(SceneInput, UnknownMaterialAndShape) {
  expectError(errorOf(replaced(kGood, "model = neo-hookean", "model = neo-hooke")),
              {"[material.steel]", "model", "neo-hooke", "did you mean 'neo-hookean'"});
  expectError(errorOf(replaced(kGood, "shape = box\nlower = 0 0\nupper = 0.2",
                               "shape = cube\nlower = 0 0\nupper = 0.2")),
              {"[body.bar]", "shape", "cube", "box"});
}

TEST(SceneInput, InvalidMaterialParameter) {
  expectError(errorOf(replaced(kGood, "poisson_ratio = 0.3", "poisson_ratio = 0.5")),
              {"[material.steel]", "nu", "0.5"});
}

TEST(SceneInput, RegionSelectingNothing) {
  expectError(errorOf(replaced(kGood, "lower = 0.19 0\nupper = 0.2 0.04",
                               "lower = 0.3 0\nupper = 0.4 0.04")),
              {"[region.tip]", "selects no particle"});
}

TEST(SceneInput, StaticRunNeedsAClampAndDamping) {
  const std::string unclamped = replaced(kGood, "[clamp.root]\nface = x-\n", "");
  expectError(errorOf(unclamped + "[static]\n[damping]\nkinetic = true\n"),
              {"[static]", "needs the body held"});
  expectError(errorOf(kGood + "[static]\n"), {"[static]", "needs damping"});
  EXPECT_EQ(errorOf(kGood + "[static]\n[damping]\nkinetic = true\n"), "");
}

TEST(SceneInput, TooManyParticles) {
  expectError(errorOf(kGood, {"--scene.dx=1e-6"}), {"[scene]", "dx", "max_particles"});
}

TEST(SceneInput, CommandLineOverrides) {
  const SceneSetup<2> setup =
      buildScene<2>(Config::parse(kGood, "scene.ini", {"--time.end=0.5", "scene.dx=0.02"}));
  EXPECT_EQ(setup.run.endTime, 0.5);
  EXPECT_EQ(setup.dx, 0.02);
  expectError(errorOf(kGood, {"--time.ned=1"}), {"command line", "[time]", "ned", "'end'"});
  expectError(errorOf(kGood, {"--timeend"}), {"command line", "--section.key=value"});
}

TEST(SceneInput, OutputFieldsNone) {
  const SceneSetup<2> setup =
      buildScene<2>(Config::parse(kGood, "scene.ini", {"--output.fields=none"}));
  EXPECT_TRUE(setup.output.fields.empty());
  expectError(errorOf(kGood, {"--output.fields=displacment"}),
              {"[output]", "fields", "did you mean 'displacement'"});
}

TEST(SceneInput, UnnamedNamedSection) {
  expectError(errorOf(kGood + "[material]\nmodel = neo-hookean\n"), {"[material]", "need a name"});
}

TEST(SceneInput, ThinClampIsRejected) {
  expectError(errorOf(replaced(kGood, "face = x-", "face = x-\nlayers = 1")),
              {"[clamp.root]", "layers", "needs 3"});
}

TEST(SceneInput, ExamplesBuild) {
  for (const char* name :
       {"cantilever", "oscillating_plate", "clamped_plate", "hourglass_block", "hourglass_beam"}) {
    const std::string path = std::string(TLSPH_SOURCE_DIR) + "/examples/" + name + ".ini";
    const Config config = Config::read(path);
    if (sceneDimension(config) == 2)
      EXPECT_NO_THROW(buildScene<2>(config)) << path;
    else
      EXPECT_NO_THROW(buildScene<3>(config)) << path;
  }
}

TEST(SceneInput, BadClampMethodAndFace) {
  expectError(errorOf(replaced(kGood, "face = x-", "face = x-\nmethod = mirrored")),
              {"scene.ini", "[clamp.root]", "method", "'mirrored'", "mirror", "fixed"});
  expectError(errorOf(replaced(kGood, "face = x-", "face = z-")),
              {"[clamp.root]", "face", "'z-'", "x-", "y+"});
  expectError(errorOf(replaced(kGood, "face = x-", "face = left")),
              {"[clamp.root]", "face", "'left'"});
  expectError(errorOf(replaced(kGood, "face = x-", "face = x-\nmotion = spin")),
              {"[clamp.root]", "motion", "'spin'", "rotation"});
  expectError(errorOf(replaced(kGood, "face = x-", "face = x-\nmotion = displacement")),
              {"[clamp.root]", "value", "missing"});
  // The quadratic extrapolation needs one body layer more than the ghost layers.
  const std::string thin = replaced(
      replaced(kGood, "lower = 0.19 0\nupper = 0.2 0.04", "lower = 0.02 0\nupper = 0.03 0.04"),
      "upper = 0.2 0.04", "upper = 0.03 0.04");
  EXPECT_EQ(errorOf(thin), "");  // three layers: enough for the odd reflection
}

// Where the body is too thin behind a mirrored face, the ghosts fall back (a warning says
// how many): to the odd reflection without a second layer, to fixed ghosts without a mirror.
TEST(SceneInput, ThinBodyBehindAMirroredFaceFallsBack) {
  const std::string thin = replaced(
      replaced(kGood, "lower = 0.19 0\nupper = 0.2 0.04", "lower = 0.01 0\nupper = 0.02 0.04"),
      "upper = 0.2 0.04", "upper = 0.02 0.04");  // two layers behind x-
  const SceneSetup<2> odd = buildScene<2>(Config::parse(thin, "scene.ini"));
  ASSERT_EQ(odd.warnings.size(), 1u);
  EXPECT_NE(odd.warnings[0].find("4 of the 12 ghosts have no body particle to mirror"),
            std::string::npos)
      << odd.warnings[0];
  EXPECT_EQ(odd.scene.mirrorGhosts.size(), 8u);
  ASSERT_EQ(odd.scene.prescriptions.size(), 1u);
  EXPECT_EQ(odd.scene.prescriptions[0].particles.size(), 4u);  // layer-3 ghosts held fixed

  const SceneSetup<2> quadratic = buildScene<2>(Config::parse(
      replaced(thin, "face = x-", "face = x-\nmethod = mirror-quadratic"), "scene.ini"));
  ASSERT_EQ(quadratic.warnings.size(), 2u);
  EXPECT_NE(quadratic.warnings[1].find("4 ghosts have no second body layer"), std::string::npos)
      << quadratic.warnings[1];
}

TEST(SceneInput, MovingClampIsAPrescriptionFollowedByItsGhosts) {
  const SceneSetup<2> setup = buildScene<2>(Config::parse(
      replaced(kGood, "face = x-", "face = x-\nmotion = displacement\nvalue = 0.001 0\nramp = 0.1"),
      "scene.ini"));
  ASSERT_EQ(setup.scene.prescriptions.size(), 1u);
  const auto& rule = setup.scene.prescriptions[0];
  EXPECT_EQ(rule.name, "clamp.root");
  EXPECT_TRUE(rule.particles.empty());  // mirrored: the ghosts follow by reflection
  EXPECT_EQ(rule.motion, PrescribedMotion::Displacement);
  EXPECT_EQ(setup.scene.mirrorGhosts.size(), 3u * 4u);
  for (const auto& m : setup.scene.mirrorGhosts)
    EXPECT_EQ(m.motion, 0);
}

// The clamp's ghost layers continue the bodies' lattice exactly: along each axis, all the
// scene's coordinates are whole spacings apart, the same spacing on every axis.
TEST(SceneInput, GhostsContinueTheExactLattice) {
  const auto setup = buildScene<2>(Config::parse(kGood, "scene.ini"));
  const auto& X = setup.scene.particles.referencePosition;
  ASSERT_GT(setup.scene.mirrorGhosts.size(), 0u);
  const double spacing = (X[1] - X[0]).norm();  // two neighbours in the body (along y)
  EXPECT_NEAR(spacing, 0.01, 1e-15);
  for (const auto& x : X)
    for (int a = 0; a < 2; ++a) {
      const double offset = x[a] - X[0][a];
      ASSERT_EQ(offset, std::round(offset / spacing) * spacing) << x.transpose();
    }
}

// The bodies are numbered with their longest axis slowest (LocalityOrder.hpp): the 0.2 x 0.04
// bar column by column along x, the ghosts after them.
TEST(SceneInput, BodiesAreNumberedWithTheLongestAxisSlowest) {
  const auto setup = buildScene<2>(Config::parse(kGood, "scene.ini"));
  const auto& X = setup.scene.particles.referencePosition;
  ASSERT_EQ(setup.body.size(), X.size());
  Index bodies = 0;
  while (bodies < static_cast<Index>(X.size()) && setup.ghost[bodies] == 0)
    ++bodies;
  EXPECT_EQ(bodies, 20 * 4);
  for (Index i = 1; i < bodies; ++i)
    ASSERT_TRUE(X[i - 1][0] < X[i][0] || (X[i - 1][0] == X[i][0] && X[i - 1][1] < X[i][1])) << i;
  for (Index i = bodies; i < static_cast<Index>(X.size()); ++i)
    EXPECT_EQ(setup.ghost[i], 1);
}

// Region faces through cell centres: which particles a region selects is decided at
// (n + 1/2) dx as evaluated in double, where the fill decides which cells are particles, not at
// the particles' positions on the exact grid (which differ from it in the last bits).
TEST(SceneInput, RegionFacesThroughCellCentresDecideAsTheFill) {
  const double dx = 0.01;
  const std::string body = replaced(kGood, "upper = 0.2 0.04\n[clamp", "upper = 1 0.04\n[clamp");
  auto centre = [&](int n) { return (n + 0.5) * dx; };  // the formula's centre of column n
  int differ = 0;
  for (int n = 0; n + 10 < 100; n += 3) {
    std::ostringstream box;
    box << std::setprecision(17) << "lower = " << centre(n) << " 0\nupper = " << centre(n + 10)
        << " 0.04";
    const std::string text = replaced(body, "lower = 0.19 0\nupper = 0.2 0.04", box.str());
    const auto setup = buildScene<2>(Config::parse(text, "scene.ini"));
    const auto& X = setup.scene.particles.referencePosition;
    const auto& tip = setup.regions.at("tip");
    EXPECT_EQ(tip.size(), 4u * 11u) << box.str();  // columns n to n + 10, both faces' included
    for (Index i : tip)
      for (int m : {n, n + 10})
        differ += X[i][0] != centre(m) && std::abs(X[i][0] - centre(m)) < 1e-12;
  }
  // The test means something only where the grid's coordinate is not the formula's.
  EXPECT_GT(differ, 0);
}

TEST(SceneInput, LoadOnAFaceTakesTheSurfaceLayerOnly) {
  // A half-space catching two layers at x+: a traction warns; face = x+ takes one layer.
  const std::string twoLayers = replaced(replaced(kGood, "lower = 0.19 0", "lower = 0.18 0"),
                                         "type = force", "type = traction");
  const SceneSetup<2> warned = buildScene<2>(Config::parse(twoLayers, "scene.ini"));
  ASSERT_EQ(warned.warnings.size(), 1u);
  for (const std::string part :
       {"[load.pull]", "2 of the 8 particles", "not on the body's surface", "face = "})
    EXPECT_NE(warned.warnings[0].find(part), std::string::npos) << warned.warnings[0];
  EXPECT_EQ(warned.scene.loads[0].particles.size(), 8u);

  const SceneSetup<2> face =
      buildScene<2>(Config::parse(replaced(twoLayers, "region = tip", "face = x+"), "scene.ini"));
  EXPECT_TRUE(face.warnings.empty());
  ASSERT_EQ(face.scene.loads[0].particles.size(), 4u);
  double total = 0.0;
  for (std::size_t k = 0; k < 4; ++k) {
    const Index i = face.scene.loads[0].particles[k];
    EXPECT_NEAR(face.scene.particles.referencePosition[i].x(), 0.195, 1e-12);
    total += face.scene.loads[0].force[k].x();
  }
  EXPECT_NEAR(total, 10.0 * 0.04, 1e-12);  // traction x the face's length

  // face and region together: the face's particles inside the region.
  const SceneSetup<2> both = buildScene<2>(Config::parse(
      replaced(replaced(twoLayers, "upper = 0.2 0.04\n[load", "upper = 0.2 0.02\n[load"),
               "region = tip", "region = tip\nface = x+"),
      "scene.ini"));
  EXPECT_EQ(both.scene.loads[0].particles.size(), 2u);

  expectError(errorOf(replaced(kGood, "region = tip", "face = x")),
              {"[load.pull]", "face", "'x'", "x+"});
  expectError(errorOf(replaced(kGood, "region = tip", "region = tip\nface = x-")),
              {"[load.pull]", "face", "no particle on face x-"});
}

TEST(SceneInput, HolesRemoveParticles) {
  const std::string withHole =
      kGood + "[hole.h]\nshape = cylinder\ncentre = 0.1 0.02\nradius = 0.011\n";
  const SceneSetup<2> setup = buildScene<2>(Config::parse(withHole, "scene.ini"));
  const SceneSetup<2> plain = buildScene<2>(Config::parse(kGood, "scene.ini"));
  // The disc of radius 1.1 dx around a lattice corner holds the 4 cell centres at 0.71 dx.
  EXPECT_EQ(plain.scene.particles.size() - setup.scene.particles.size(), 4);
  for (Index i = 0; i < setup.scene.particles.size(); ++i)
    EXPECT_GT((setup.scene.particles.referencePosition[i] - Vec<2>(0.1, 0.02)).norm(), 0.011);
  expectError(errorOf(kGood + "[hole.h]\nshape = half-space\npoint = 0 0\nnormal = 1 0\n"),
              {"[hole.h]", "shape", "'half-space'"});
}

TEST(SceneInput, RandomInitialVelocityIsSeededAndBounded) {
  auto velocities = [](const std::string& seed, const std::string& amplitude = "0.5") {
    const SceneSetup<2> s = buildScene<2>(Config::parse(
        kGood + "[initial.kick]\nprofile = random\namplitude = " + amplitude + "\n" + seed,
        "scene.ini"));
    return s.scene.particles.velocity;
  };
  const auto a = velocities("seed = 7\n"), b = velocities("seed = 7\n"),
             c = velocities("seed = 8\n");
  ASSERT_EQ(a.size(), b.size());
  double largest = 0.0, mean = 0.0;
  bool differs = false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i], b[i]);  // same seed, same field
    differs = differs || a[i] != c[i];
    largest = std::max(largest, a[i].cwiseAbs().maxCoeff());
    mean += a[i].x();
  }
  EXPECT_TRUE(differs);
  EXPECT_LE(largest, 0.5);
  EXPECT_GT(largest, 0.4);  // the components fill [-0.5, 0.5]
  EXPECT_LT(std::abs(mean / a.size()), 0.1);
  EXPECT_THROW(velocities("seed = 1\n", "0"), InputError);
}

// The draws follow the lattice (y slowest, x fastest), not the particles' numbering (x slowest
// for this bar): a particle's velocity depends on its place only.
TEST(SceneInput, RandomInitialVelocityIsDrawnInTheLatticesOrder) {
  const SceneSetup<2> s = buildScene<2>(Config::parse(
      kGood + "[initial.kick]\nprofile = random\namplitude = 0.5\nseed = 7\n", "scene.ini"));
  const auto& X = s.scene.particles.referencePosition;
  std::vector<Index> lattice;
  for (Index i = 0; i < static_cast<Index>(X.size()); ++i)
    if (s.ghost[i] == 0) lattice.push_back(i);
  ASSERT_EQ(lattice.size(), 80u);
  std::sort(lattice.begin(), lattice.end(), [&](Index i, Index j) {
    return X[i].y() < X[j].y() || (X[i].y() == X[j].y() && X[i].x() < X[j].x());
  });
  EXPECT_NE(lattice[1], 1);  // the numbering is not the lattice's order
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (Index i : lattice)
    for (int a = 0; a < 2; ++a)
      ASSERT_EQ(s.scene.particles.velocity[i][a], 0.5 * unit(rng)) << i;
}

// The Taylor quadrature warns (naming the material) on a nearly incompressible material, where
// its volumetric term stiffens coarse resolutions; not on a compressible one, not when nodal.
TEST(SceneInput, TaylorQuadratureWarnsOnNearlyIncompressibleMaterial) {
  auto warningsOf = [](const std::string& text) {
    return buildScene<2>(Config::parse(text, "scene.ini")).warnings;
  };
  const std::string taylor = kGood + std::string("[kernel]\nquadrature = taylor\n");
  EXPECT_TRUE(warningsOf(taylor).empty());
  const auto w = warningsOf(replaced(taylor, "poisson_ratio = 0.3", "poisson_ratio = 0.49"));
  ASSERT_EQ(w.size(), 1u);
  for (const char* part :
       {"scene.ini", "poisson_ratio 0.49", "quadrature = taylor", "quadrature = nodal"})
    EXPECT_NE(w[0].find(part), std::string::npos) << part << " in " << w[0];
  const std::string nodal = kGood + std::string("[kernel]\nquadrature = nodal\n");
  EXPECT_TRUE(warningsOf(replaced(nodal, "poisson_ratio = 0.3", "poisson_ratio = 0.49")).empty());
}
