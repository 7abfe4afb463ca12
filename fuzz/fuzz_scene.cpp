// libFuzzer target for the scene parser and the scene set-up (Config::parse + buildScene): any
// input must end in a scene or in one of the errors a user can act on (InputError, SetupError,
// MaterialError), never in a crash, a hang or an unbounded allocation. Build and run with
// `bash scripts/setup.sh fuzz` (clang, -fsanitize=fuzzer,address,undefined; seeds: examples/
// and validation/scenes/). An input it reports goes to tests/fuzz-regressions/
// (test_fuzz_regressions).
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <new>
#include <string>

#include "materials/ElasticConstants.hpp"
#include "model/Errors.hpp"
#include "scene/Config.hpp"
#include "scene/InputError.hpp"
#include "scene/SceneBuilder.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > 8192) return 0;  // scene files are small; long inputs only slow the search
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    // The particle limit keeps each set-up within the fuzzer's time and memory budget; the
    // limit itself is what stops absurd particle counts (test_scene_input).
    const tlsph::Config config =
        tlsph::Config::parse(text, "fuzz.ini", {"--scene.max_particles=20000"});
    if (tlsph::sceneDimension(config) == 2)
      tlsph::buildScene<2>(config);
    else
      tlsph::buildScene<3>(config);
  } catch (const tlsph::InputError&) {
  } catch (const tlsph::SetupError&) {
  } catch (const tlsph::MaterialError&) {
  }
  // Anything else (std::bad_alloc, std::out_of_range, ...) escapes and libFuzzer reports it.
  return 0;
}
