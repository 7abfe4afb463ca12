// Bad scene input gets a clear error naming the file, the section, the key and what was
// expected; good input builds the scene it describes.
#include <gtest/gtest.h>

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
  for (const char* name : {"cantilever", "oscillating_plate", "clamped_plate"}) {
    const std::string path = std::string(TLSPH_SOURCE_DIR) + "/examples/" + name + ".ini";
    const Config config = Config::read(path);
    if (sceneDimension(config) == 2)
      EXPECT_NO_THROW(buildScene<2>(config)) << path;
    else
      EXPECT_NO_THROW(buildScene<3>(config)) << path;
  }
}
