// [gravity], [load.NAME] and [initial.NAME]: what drives the bodies.
#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "geometry/LocalityOrder.hpp"
#include "scene/Builder.hpp"

namespace tlsph::scene_build {

template <int D>
void Builder<D>::readLoads() {
  SectionReader g(config_, "gravity");
  setup_.scene.gravity = g.vector<D>("acceleration", Vec<D>::Zero());
  setup_.scene.gravityRamp.duration = g.nonNegative("ramp", 0.0);
  g.finish();
  if (!setup_.scene.gravity.isZero())
    setup_.conditions.push_back("gravity " + fmt<D>(setup_.scene.gravity) + " m/s^2");
  const auto& p = setup_.scene.particles;
  for (const auto& name : config_.namesOf("load")) {
    SectionReader r(config_, "load." + name);
    Load<D> load;
    load.name = "load." + name;
    const std::string regionName = r.has("region") ? config_.get("load." + name, "region") : "";
    load.particles = region(r);
    std::string where = regionName.empty() ? "" : " of region '" + regionName + "'";
    // A mesh body's named surface: its particles, each with its share of the true area.
    const SurfacePatch<D>* surface = nullptr;
    std::string faceName;
    if (r.has("surface")) {
      if (r.has("face")) throw r.error("face", "give either face or surface, not both");
      if (!regionName.empty())
        throw r.error("region",
                      "a load on a named surface acts on the whole surface; give "
                      "either region or surface");
      const std::string surfaceName = config_.get("load." + name, "surface");
      surface = &namedSurface(r);
      load.particles = surface->particles;
      where = " on surface " + surfaceName;
    } else if (r.has("face")) {
      // The surface layer of the bodies' face (as for clamps), within the region if given.
      faceName = r.word("face", std::nullopt, faceNames());
      std::vector<Index> onFace;
      for (Index i : load.particles)
        if (onBoundingFace(i, faceName)) onFace.push_back(i);
      if (onFace.empty())
        throw r.error("face", "the region '" + (regionName.empty() ? "all" : regionName) +
                                  "' has no particle on face " + faceName +
                                  " (the layer of particles at the bodies' extreme along " +
                                  faceName + ")");
      load.particles = std::move(onFace);
      where = " on face " + faceName + where;
    }
    const std::string type = r.word("type", std::nullopt, {"traction", "force", "pressure"});
    Vec<D> value = Vec<D>::Zero();
    double pressure = 0.0;
    bool follow = false;
    if (type == "pressure") {
      pressure = r.number("value");
      // A following pressure acts on the present shape of the surface's facets, which only a
      // named surface of a mesh body has.
      follow = r.flag("follow", false);
      if (follow && !surface)
        throw r.error(
            "follow",
            "a following pressure acts on a named surface of a mesh body (surface = "
            "NAME), whose facets it follows as they move; " +
                (faceName.empty() ? std::string("this load has none")
                                  : "face " + faceName + " of the bounding box has none"));
      // Pressure pushes against the outward normal: it needs the surface's normals and areas,
      // which a named surface has and a lattice face has exactly (dx^(d-1) per particle).
      if (!surface && (faceName.empty() || setup_.freeForm))
        throw r.error("type", setup_.freeForm
                                  ? "pressure acts on a named surface (surface = NAME): a face "
                                    "of a particle set has no known area"
                                  : "pressure acts on a face of the bodies' bounding box (face "
                                    "= x-, ...) or on a named surface of a mesh body");
    } else {
      if (r.has("follow"))
        throw r.error("follow",
                      "only a pressure follows the surface (type = pressure), not a " + type);
      value = r.vector<D>("value");
    }
    load.ramp.duration = r.nonNegative("ramp", 0.0);
    r.finish();
    if (type == "traction" && !surface && !setup_.freeForm) warnInteriorTraction(load, regionName);
    if (surface) {
      // The surface's integrals: A_I = int lambda_I dA and a_I = int lambda_I n dA, so that the
      // particles' forces add up to the load over the true area.
      for (std::size_t k = 0; k < surface->particles.size(); ++k)
        load.force.push_back(type == "pressure" ? Vec<D>(-pressure * surface->areaVector[k])
                             : type == "traction"
                                 ? Vec<D>(surface->area[k] * value)
                                 : Vec<D>(surface->area[k] / surface->measure * value));
    } else if (type == "pressure") {
      // A lattice face: each surface particle carries dx^(d-1) of it.
      Vec<D> outward = Vec<D>::Zero();
      outward[faceName[0] - 'x'] = faceName[1] == '-' ? -1.0 : 1.0;
      for (std::size_t k = 0; k < load.particles.size(); ++k)
        load.force.push_back(-pressure * std::pow(setup_.dx, D - 1) * outward);
    } else {
      double volume = 0.0;
      for (Index i : load.particles)
        volume += p.volume[i];
      for (Index i : load.particles) {
        // (6.76): a traction acts on the area a_I = V_I^((d-1)/d) of each surface particle.
        const double share =
            type == "traction" ? std::pow(p.volume[i], (D - 1.0) / D) : p.volume[i] / volume;
        load.force.push_back(share * value);
      }
    }
    if (follow) {
      load.following.emplace(surface->facets, pressure);
      if (setup_.followingLoad.empty()) {
        setup_.followingLoad = load.name;
        setup_.followingWhere = config_.where(load.name, "follow");
      }
    }
    if (type == "pressure") {
      setup_.conditions.push_back(load.name + ": " + (follow ? "following " : "") + "pressure " +
                                  fmt(pressure) + " Pa on " +
                                  std::to_string(load.particles.size()) + " particles" + where);
      setup_.scene.loads.push_back(std::move(load));
      continue;
    }
    setup_.conditions.push_back(load.name + ": " + type + " " + fmt<D>(value) + " on " +
                                std::to_string(load.particles.size()) + " particles" + where);
    setup_.scene.loads.push_back(std::move(load));
  }
}

// A traction acts on the area dx^(d-1) of each particle it is given to, so a region that
// holds particles below the surface applies it more than once: say so.
template <int D>
void Builder<D>::warnInteriorTraction(const Load<D>& load, const std::string& regionName) {
  const auto& X = setup_.scene.particles.referencePosition;
  Index interior = 0, example = -1;
  for (Index i : load.particles) {
    bool surface = false;
    for (int a = 0; a < D && !surface; ++a)
      for (double s : {-1.0, 1.0}) {
        Vec<D> Y = X[i];
        Y[a] += s * setup_.dx;
        if (latticeParticle(Y) < 0) surface = true;
      }
    if (!surface && interior++ == 0) example = i;
  }
  if (interior == 0) return;
  setup_.warnings.push_back(
      config_.where(load.name, regionName.empty() ? "" : "region") + ": [" + load.name + "] " +
      std::to_string(interior) + " of the " + std::to_string(load.particles.size()) +
      " particles the traction acts on are not on the body's surface (e.g. particle " +
      std::to_string(example) + " at " + fmt<D>(X[example]) +
      "): each gets the traction times its area dx^" + std::to_string(D - 1) +
      ", so the load counts the layers below the surface too; give face = x-|x+|... (with "
      "the region) to load the surface layer only");
}

template <int D>
void Builder<D>::readInitialConditions() {
  auto& p = setup_.scene.particles;
  for (const auto& name : config_.namesOf("initial")) {
    SectionReader r(config_, "initial." + name);
    const auto& particles = region(r);
    const std::string profile =
        r.word("profile", "constant", {"constant", "beam-mode", "rotation", "random"});
    if (profile == "random") {
      // Each component uniform in [-amplitude, amplitude], from a seeded generator: a
      // reproducible excitation of every mode, the spurious ones included. Drawn in the
      // lattice's order (latticeOrderBefore), not the particles' numbering, so
      // that a particle's velocity depends on its place only (LocalityOrder.hpp numbers the
      // particles otherwise).
      const double amplitude = r.positive("amplitude");
      const long seed = r.integer("seed", 1);
      std::mt19937_64 rng(static_cast<std::uint64_t>(seed));
      std::uniform_real_distribution<double> unit(-1.0, 1.0);
      std::vector<Index> drawOrder(particles);
      const auto& X = p.referencePosition;
      std::stable_sort(drawOrder.begin(), drawOrder.end(),
                       [&](Index i, Index j) { return latticeOrderBefore<D>(X[i], X[j]); });
      for (Index i : drawOrder)
        for (int a = 0; a < D; ++a)
          p.velocity[i][a] = amplitude * unit(rng);
      setup_.conditions.push_back("initial." + name + ": random velocity, components up to " +
                                  fmt(amplitude) + " m/s, seed " + std::to_string(seed));
    } else if (profile == "constant") {
      const Vec<D> v = r.vector<D>("velocity");
      for (Index i : particles)
        p.velocity[i] = v;
      setup_.conditions.push_back("initial." + name + ": velocity " + fmt<D>(v));
    } else if (profile == "rotation") {
      // A rigid spin: v = rate axis x (X - point).
      const Vec3 axis = rotationAxis<D>(r);
      const Vec<D> point = r.vector<D>("point");
      const double rate = r.number("rate");
      for (Index i : particles)
        p.velocity[i] = rotationVelocity<D>(axis, rate, Vec<D>(p.referencePosition[i] - point));
      setup_.conditions.push_back("initial." + name + ": rotation " +
                                  rotationText<D>(axis, point, rate));
    } else {
      // First cantilever mode shape (docs/method.md section 6, oscillating plate):
      // v(s) = amplitude f(s)/f(L) along `direction`, s the distance from `origin` along `axis`.
      const std::string axisName = r.word("axis", "x", {"x", "y", "z"});
      const int axis = axisName[0] - 'x';
      if (axis >= D) throw r.error("axis", "the scene is 2D");
      const Vec<D> direction = r.vector<D>("direction");
      if (direction.isZero()) throw r.error("direction", "must not be zero");
      const double origin = r.number("origin", 0.0);
      const double length = r.positive("length");
      const double kL = r.positive("kL", 1.875);
      double amplitude = 0.0;
      if (r.has("amplitude_over_c0")) {
        // c0 = sqrt(K / rho0) of the region's first particle's material (Gray et al. 2001).
        const auto& m = setup_.scene.materials[p.material[particles.front()]];
        amplitude =
            r.number("amplitude_over_c0") * std::sqrt(elasticConstants(m).bulkModulus / density(m));
      } else {
        amplitude = r.number("amplitude");
      }
      const double k = kL / length;
      auto f = [&](double s) {
        return (std::sin(kL) + std::sinh(kL)) * (std::cos(k * s) - std::cosh(k * s)) -
               (std::cos(kL) + std::cosh(kL)) * (std::sin(k * s) - std::sinh(k * s));
      };
      const double fL = f(length);
      for (Index i : particles)
        p.velocity[i] =
            amplitude * f(p.referencePosition[i][axis] - origin) / fL * direction.normalized();
      setup_.conditions.push_back("initial." + name + ": beam-mode, tip speed " + fmt(amplitude) +
                                  " m/s");
    }
    r.allow({"velocity", "amplitude", "amplitude_over_c0", "axis", "direction", "origin", "length",
             "kL", "point", "rate", "seed"});
    r.finish();
  }
}

template void Builder<2>::readLoads();
template void Builder<2>::warnInteriorTraction(const Load<2>&, const std::string&);
template void Builder<2>::readInitialConditions();
template void Builder<3>::readLoads();
template void Builder<3>::warnInteriorTraction(const Load<3>&, const std::string&);
template void Builder<3>::readInitialConditions();

}  // namespace tlsph::scene_build
