#include "scene/SceneBuilder.hpp"

#include <algorithm>
#include <filesystem>
#include <iomanip>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "geometry/LatticeGrid.hpp"
#include "scene/Builder.hpp"

namespace tlsph::scene_build {

template <int D>
void Builder<D>::rejectUnknownSections() {
  static const std::vector<std::string> kinds = {
      "scene",   "kernel",    "hourglass", "time",    "static", "damping",
      "gravity", "output",    "material",  "body",    "hole",   "region",
      "clamp",   "prescribe", "load",      "initial", "probe",  "artificial_viscosity",
      "guard",   "checkpoint"};
  for (const auto& section : config_.sections()) {
    const std::string kind = section.substr(0, section.find('.'));
    if (std::find(kinds.begin(), kinds.end(), kind) != kinds.end()) continue;
    const std::string hint = closestMatch(kind, kinds);
    throw InputError(config_.where(section, ""), section, "",
                     "unknown section" + (hint.empty() ? "" : "; did you mean [" + hint + "]?"));
  }
}

template <int D>
void Builder<D>::readSceneSection() {
  SectionReader r(config_, "scene");
  r.allow({"dimension"});
  setup_.sourceFile = config_.origin();
  setup_.name = r.word("name", std::filesystem::path(config_.origin()).stem().string());
  if (setup_.name.empty() || setup_.name.find_first_of("/\\") != std::string::npos)
    throw r.error("name", "must be a file name without '/' (it names the output files), got '" +
                              setup_.name + "'");
  setup_.dx = r.positive("dx");
  if (!latticeSpacingUsable(setup_.dx))
    throw r.error(
        "dx", "must lie between 2^-960 and 2^960 (about 1e-289 and 1e289), got " + fmt(setup_.dx));
  const long most = r.integer("max_particles", 5'000'000);
  if (most < 1) throw r.error("max_particles", "must be at least 1, got " + fmt(double(most)));
  maxParticles_ = static_cast<std::size_t>(most);
  r.finish();
}

template void Builder<2>::rejectUnknownSections();
template void Builder<2>::readSceneSection();
template void Builder<3>::rejectUnknownSections();
template void Builder<3>::readSceneSection();

}  // namespace tlsph::scene_build

namespace tlsph {

int sceneDimension(const Config& config) {
  SectionReader r(config, "scene");
  const std::string d = r.word("dimension", std::nullopt, {"2", "3"});
  return d == "2" ? 2 : 3;
}

template <int D>
SceneSetup<D> buildScene(const Config& config) {
  SceneSetup<D> setup = scene_build::Builder<D>(config).build();
  const double dx = setup.dx;
  if (!setup.coarsenable) return setup;
  setup.coarsen = [config, dx](int factor) -> std::unique_ptr<Scene<D>> {
    std::ostringstream spacing;
    spacing << std::setprecision(17) << factor * dx;
    try {
      // The coarse levels only precondition: they skip the integration constraint's solve.
      Config coarse = config.with("scene.dx", spacing.str(), "multigrid coarsening")
                          .with("kernel.integration_constraint", "false", "multigrid coarsening");
      return std::make_unique<Scene<D>>(scene_build::Builder<D>(coarse).build().scene);
    } catch (const std::exception&) {
      return nullptr;  // too coarse for this geometry: no such level
    }
  };
  return setup;
}

template SceneSetup<2> buildScene<2>(const Config&);
template SceneSetup<3> buildScene<3>(const Config&);

}  // namespace tlsph
