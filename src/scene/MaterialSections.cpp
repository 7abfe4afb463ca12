// [material.NAME]: the constitutive model, its density and elastic constants.
#include <algorithm>
#include <string>
#include <vector>

#include "scene/Builder.hpp"

namespace tlsph::scene_build {

template <int D>
void Builder<D>::readMaterials() {
  const auto names = config_.namesOf("material");
  if (names.empty())
    throw InputError(config_.origin(), "material.NAME", "",
                     "the scene needs at least one [material.NAME] section");
  std::vector<std::string> models;
  for (auto m : materialNames())
    models.emplace_back(m);
  for (const auto& name : names) {
    SectionReader r(config_, "material." + name);
    const std::string model = r.word("model", std::nullopt, models);
    const double density = r.positive("density");
    ElasticConstants c;
    // One pair of constants. A constant out of its range is reported at its own key: the
    // first of each pair is a modulus that must be positive, else the second is to blame.
    auto pair = [&](const std::string& first, const std::string& second, auto make) {
      const double a = r.number(first), b = r.number(second);
      try {
        return make(a, b);
      } catch (const MaterialError& e) {
        throw r.error(a > 0.0 ? second : first, e.what());
      }
    };
    if (r.has("youngs_modulus") || r.has("poisson_ratio")) {
      c = pair("youngs_modulus", "poisson_ratio", ElasticConstants::fromYoungPoisson);
    } else if (r.has("lame_lambda")) {
      c = pair("shear_modulus", "lame_lambda",
               [](double mu, double lambda) { return ElasticConstants::fromLame(lambda, mu); });
    } else if (r.has("shear_modulus") && r.has("bulk_modulus")) {
      c = pair("shear_modulus", "bulk_modulus", ElasticConstants::fromShearBulk);
    } else {
      throw r.error("",
                    "give the elastic constants as youngs_modulus + poisson_ratio, "
                    "lame_lambda + shear_modulus, or shear_modulus + bulk_modulus");
    }
    try {
      if (model == "mooney-rivlin") {
        const double fraction = r.number("c01_fraction", 0.5);
        try {
          setup_.scene.materials.push_back(MooneyRivlin(c, density, fraction));
        } catch (const MaterialError& e) {
          throw r.error("c01_fraction", e.what());
        }
      } else {
        setup_.scene.materials.push_back(makeMaterial(model, c, density));
      }
    } catch (const MaterialError& e) {
      throw r.error("", e.what());
    }
    r.allow({"c01_fraction"});
    r.finish();
    setup_.materialNames.push_back(name);
  }
}

// The Taylor term's volumetric part, lambda (tr e_a)^2, constrains the gradient of the
// volume change as well as the change: near nu = 1/2 that stiffens coarse resolutions
// (README, Quadrature).
template <int D>
void Builder<D>::warnNearlyIncompressible() {
  const auto names = config_.namesOf("material");
  for (std::size_t m = 0; m < names.size(); ++m) {
    const auto& c = elasticConstants(setup_.scene.materials.at(m));
    const double nu = c.lambda / (2.0 * (c.lambda + c.mu));
    if (nu < 0.45) continue;
    setup_.warnings.push_back(
        config_.where("material." + names[m], "") + ": poisson_ratio " + fmt(nu) +
        " with [kernel] quadrature = taylor: its volumetric term stiffens nearly "
        "incompressible bodies at coarse resolution (Cook's membrane, nu = 0.4999, 8 particles "
        "along the clamped edge: corner -10.5 % against the FEM, -6.4 % with quadrature = "
        "nodal); give [kernel] quadrature = nodal for such a body");
  }
}

template <int D>
std::uint16_t Builder<D>::materialIndex(SectionReader& r) {
  const auto& names = setup_.materialNames;
  if (!r.has("material")) {
    if (names.size() == 1) return 0;
    throw r.error("material", "missing: the scene has several materials, name one");
  }
  const std::string m = r.word("material", std::nullopt, names);
  return static_cast<std::uint16_t>(std::find(names.begin(), names.end(), m) - names.begin());
}

template void Builder<2>::readMaterials();
template void Builder<2>::warnNearlyIncompressible();
template std::uint16_t Builder<2>::materialIndex(SectionReader&);
template void Builder<3>::readMaterials();
template void Builder<3>::warnNearlyIncompressible();
template std::uint16_t Builder<3>::materialIndex(SectionReader&);

}  // namespace tlsph::scene_build
