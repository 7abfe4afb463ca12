// [output], [checkpoint], [guard] and [probe.NAME]: what a run writes, keeps and watches.
#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "geometry/LocalityOrder.hpp"
#include "method/Kernel.hpp"
#include "scene/Builder.hpp"

namespace tlsph::scene_build {

namespace {

// The position in `candidates` of the particle nearest to `point`; of equally near ones the
// first in the lattice's order (latticeOrderBefore), so that the choice depends on the
// particles' places, not on their numbering.
template <int D>
std::size_t nearestTo(const Vec<D>& point, const std::vector<Vec<D>>& X,
                      const std::vector<Index>& candidates) {
  std::size_t best = 0;
  for (std::size_t k = 1; k < candidates.size(); ++k) {
    const Vec<D>&Y = X[candidates[k]], &B = X[candidates[best]];
    const double dk = (Y - point).squaredNorm(), db = (B - point).squaredNorm();
    if (dk < db || (dk == db && latticeOrderBefore<D>(Y, B))) best = k;
  }
  return best;
}

const std::vector<std::string> kFieldNames = {"displacement",    "velocity",      "J",
                                              "von_mises",       "cauchy_stress", "first_piola",
                                              "hourglass_error", "flags"};

}  // namespace

template <int D>
void Builder<D>::readOutput() {
  SectionReader o(config_, "output");
  setup_.output.directory = o.word("directory", "output/" + setup_.name);
  std::error_code status;
  if (setup_.output.directory.empty())
    throw o.error("directory", "must not be empty (give '.' for the working directory)");
  if (std::filesystem::exists(setup_.output.directory, status) &&
      !std::filesystem::is_directory(setup_.output.directory, status))
    throw o.error("directory", "'" + setup_.output.directory + "' exists and is not a directory");
  setup_.output.fields = o.words("fields", {"displacement", "velocity", "von_mises", "flags"});
  if (setup_.output.fields.size() == 1 && setup_.output.fields[0] == "none")
    setup_.output.fields.clear();
  for (const auto& f : setup_.output.fields)
    if (std::find(kFieldNames.begin(), kFieldNames.end(), f) == kFieldNames.end()) {
      const std::string hint = closestMatch(f, kFieldNames);
      std::string all;
      for (const auto& n : kFieldNames)
        all += (all.empty() ? "" : ", ") + n;
      throw o.error("fields", "unknown field '" + f + "'" +
                                  (hint.empty() ? "" : " (did you mean '" + hint + "'?)") +
                                  "; fields: " + all + " (or 'none')");
    }
  setup_.output.everySteps = o.integer("every_steps", 0);
  setup_.output.everyTime = o.nonNegative("every_time", 0.0);
  if (setup_.output.everySteps == 0 && setup_.output.everyTime == 0.0)
    setup_.output.everyTime = setup_.run.endTime / 20.0;
  setup_.output.seriesEverySteps = std::max(1L, o.integer("series_every_steps", 20));
  setup_.output.hourglassContent = o.flag("hourglass_content", false);
  setup_.output.flushSeconds = o.nonNegative("flush_every_seconds", 10.0);
  o.finish();
}

// Periodic checkpoints (app/CheckpointSchedule.hpp): by steps, by wall time, the last K kept.
template <int D>
void Builder<D>::readCheckpoint() {
  SectionReader c(config_, "checkpoint");
  setup_.checkpoint.everySteps = c.integer("every_steps", 0);
  setup_.checkpoint.everySeconds = c.nonNegative("every_seconds", 600.0);
  setup_.checkpoint.keep = c.integer("keep", 2);
  if (setup_.checkpoint.keep < 1)
    throw c.error("keep", "must be at least 1 (the newest checkpoint), got " +
                              config_.get("checkpoint", "keep"));
  c.finish();
}

// The run's stability guards (app/Guards.hpp), checked every [static] check_every steps.
template <int D>
void Builder<D>::readGuard() {
  SectionReader g(config_, "guard");
  setup_.guard.minJacobian = g.number("min_jacobian", 0.0);
  if (!(setup_.guard.minJacobian >= 0.0 && setup_.guard.minJacobian < 1.0))
    throw g.error("min_jacobian", "must be in [0, 1), got " + config_.get("guard", "min_jacobian"));
  setup_.guard.energyError = g.nonNegative("energy_error", 0.05);
  g.finish();
}

template <int D>
void Builder<D>::readProbes() {
  const auto& p = setup_.scene.particles;
  const Kernel<D> kernel(setup_.scene.kernel, setup_.scene.supportRadius);
  for (const auto& name : config_.namesOf("probe")) {
    SectionReader r(config_, "probe." + name);
    Probe<D> probe;
    probe.name = name;
    probe.point = r.vector<D>("point");
    const std::string method = r.word("method", "nearest", {"nearest", "kernel", "surface"});
    probe.method = method == "nearest"  ? ProbeMethod::Nearest
                   : method == "kernel" ? ProbeMethod::Kernel
                                        : ProbeMethod::Surface;
    const SurfacePatch<D>* surface = nullptr;
    if (probe.method == ProbeMethod::Surface) {
      surface = &namedSurface(r);
      probe.surfaceName = config_.get("probe." + name, "surface");
      probe.fitRadius = r.positive("fit_radius", 1.0) * setup_.scene.supportRadius;
    } else {
      for (const char* key : {"surface", "fit_radius"})
        if (r.has(key))
          throw r.error(key, std::string("is read only with method = surface (a stress recovered "
                                         "at a named surface)"));
    }
    probe.quantities = r.words("quantities", {"displacement"});
    for (const auto& q : probe.quantities)
      if (q != "displacement" && q != "velocity" && q != "cauchy_stress")
        throw r.error("quantities", "unknown quantity '" + q +
                                        "'; expected displacement, velocity, cauchy_stress");
    r.finish();
    if (surface) {
      resolveSurfaceProbe(probe, *surface);
    } else if (probe.method == ProbeMethod::Nearest) {
      std::vector<Index> body(bodyCount_);
      for (Index i = 0; i < bodyCount_; ++i)
        body[i] = i;
      probe.particles = {body[nearestTo<D>(probe.point, p.referencePosition, body)]};
      probe.weights = {1.0};
    } else {
      // Shepard-normalised kernel interpolation over the reference neighbourhood; each
      // particle's displacement is carried to the point with its own gradient F - 1, so the
      // probe is exact for linear fields even on the surface (a beam's tip).
      double sum = 0.0;
      for (Index i = 0; i < bodyCount_; ++i) {
        const double w = kernel.value((p.referencePosition[i] - probe.point).norm()) * p.volume[i];
        if (w > 0.0) {
          probe.particles.push_back(i);
          probe.weights.push_back(w);
          probe.offsets.push_back(probe.point - p.referencePosition[i]);
          sum += w;
        }
      }
      if (probe.particles.empty())
        throw r.error("point", "no particle within the kernel support of " + fmt<D>(probe.point));
      for (double& w : probe.weights)
        w /= sum;
    }
    setup_.probes.push_back(std::move(probe));
  }
}

// A surface probe (method = surface): the particle of the surface nearest to the point, the
// stress recovery's fit there (method/SurfaceStress.hpp) over the surface particles within
// fit_radius (in kernel supports), and the traction of each load on that surface.
template <int D>
void Builder<D>::resolveSurfaceProbe(Probe<D>& probe, const SurfacePatch<D>& surface) {
  const auto& p = setup_.scene.particles;
  const auto& X = p.referencePosition;
  const std::string section = "probe." + probe.name;
  const std::size_t best = nearestTo<D>(probe.point, X, surface.particles);
  const Index i = surface.particles[best];
  const std::string which = "the particle of surface '" + probe.surfaceName + "' nearest to " +
                            fmt<D>(probe.point) + " (particle " + std::to_string(i) + " at " +
                            fmt<D>(X[i]) + ")";
  if (p.motion[i] != Motion::Free)
    throw InputError(config_.where(section, "surface"), section, "surface",
                     which +
                         " is held or moved by a condition: there the traction is the "
                         "condition's reaction, not known in advance; a surface probe reads a "
                         "loaded or free surface");
  std::string why;
  probe.stencil = surfaceStencil<D>(i, X, surface.particles, surface.areaVector,
                                    surface.areaVector[best], probe.fitRadius, why);
  if (!probe.stencil)
    throw InputError(config_.where(section, "surface"), section, "surface",
                     "the stress recovery at " + which + " has " + why +
                         "; a finer dx or a larger fit_radius puts more surface particles in the "
                         "fit");
  probe.particles = {i};
  probe.weights = {1.0};
  // The loads on this surface, as tractions per unit reference area at particle i: a pressure
  // -p N, a traction its force over the particle's share of the area.
  for (const auto& load : setup_.scene.loads) {
    if (!config_.has(load.name, "surface") ||
        config_.get(load.name, "surface") != probe.surfaceName)
      continue;
    ProbeTraction<D> t;
    t.ramp = load.ramp;
    if (load.following)
      t.followingPressure = load.following->pressure();
    else if (config_.get(load.name, "type") == "pressure")
      t.dead = load.force[best] / surface.areaVector[best].norm();
    else
      t.dead = load.force[best] / surface.area[best];
    probe.tractions.push_back(t);
  }
}

template void Builder<2>::readOutput();
template void Builder<2>::readCheckpoint();
template void Builder<2>::readGuard();
template void Builder<2>::readProbes();
template void Builder<2>::resolveSurfaceProbe(Probe<2>&, const SurfacePatch<2>&);
template void Builder<3>::readOutput();
template void Builder<3>::readCheckpoint();
template void Builder<3>::readGuard();
template void Builder<3>::readProbes();
template void Builder<3>::resolveSurfaceProbe(Probe<3>&, const SurfacePatch<3>&);

}  // namespace tlsph::scene_build
