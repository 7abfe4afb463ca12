// Every input in tests/fuzz-regressions/ (fuzzer findings and edge cases) ends in a scene or in a
// user error, as the fuzz target (fuzz/fuzz_scene.cpp) requires: no crash, no other exception.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "materials/ElasticConstants.hpp"
#include "model/Errors.hpp"
#include "scene/Config.hpp"
#include "scene/InputError.hpp"
#include "scene/SceneBuilder.hpp"

namespace fs = std::filesystem;
using namespace tlsph;

TEST(FuzzRegressions, EveryInputEndsInASceneOrAUserError) {
  const fs::path dir = fs::path(TLSPH_SOURCE_DIR) / "tests" / "fuzz-regressions";
  int inputs = 0;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (entry.path().extension() != ".ini") continue;
    ++inputs;
    std::ifstream in(entry.path(), std::ios::binary);
    std::stringstream text;
    text << in.rdbuf();
    try {
      const Config config = Config::parse(text.str(), entry.path().filename().string(),
                                          {"--scene.max_particles=20000"});
      if (sceneDimension(config) == 2)
        buildScene<2>(config);
      else
        buildScene<3>(config);
    } catch (const InputError&) {
    } catch (const SetupError&) {
    } catch (const MaterialError&) {
    } catch (const std::exception& e) {
      ADD_FAILURE() << entry.path() << ": " << e.what();
    }
  }
  EXPECT_GE(inputs, 4);
}
