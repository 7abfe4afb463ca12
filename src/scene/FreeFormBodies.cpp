// A body that is not filled on the lattice: a particle set read from a file (shape = particles)
// or a CAD or mesh file meshed by gmsh (shape = mesh), whose named surfaces clamps and loads
// then use. Such a body is the scene's only one: its particles are taken as they are, so there
// is no lattice to decide which of two overlapping bodies a point belongs to.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <numeric>
#include <string>
#include <vector>

#include "geometry/BoundaryArea.hpp"
#include "geometry/GmshBody.hpp"
#include "geometry/LocalityOrder.hpp"
#include "io/ParticleFile.hpp"
#include "scene/Builder.hpp"
#include "scene/ParticleSetChecks.hpp"

namespace tlsph::scene_build {

namespace {

const std::vector<std::string> kFreeFormShapes = {"particles", "mesh"};

bool isFreeForm(const Config& config, const std::string& body) {
  const ConfigEntry* e = config.find("body." + body, "shape");
  return e && std::find(kFreeFormShapes.begin(), kFreeFormShapes.end(), e->value) !=
                  kFreeFormShapes.end();
}

// A file a scene names, relative to the scene file's folder (or to the working folder for
// a scene given on the command line only).
std::filesystem::path sceneRelative(const Config& config, const std::string& name) {
  const std::filesystem::path file(name);
  if (file.is_absolute()) return file;
  const std::filesystem::path scene(config.origin());
  if (config.origin() == "command line" || !scene.has_parent_path()) return file;
  return scene.parent_path() / file;
}

// A named surface as loads use it: per particle the area A_I = int lambda_I dA and the vector
// area a_I = int lambda_I n dA, both integrated on gmsh's curved (order-2) surface.
template <int D>
SurfacePatch<D> surfacePatch(const typename MeshedBody<D>::Surface& s) {
  SurfacePatch<D> patch;
  patch.particles = s.nodes;
  patch.area = s.area;
  patch.areaVector = s.areaVector;
  patch.facets = s.facets;
  patch.measure = s.measure;
  return patch;
}

}  // namespace

template <int D>
bool Builder<D>::freeFormBodyGiven() const {
  for (const auto& name : config_.namesOf("body"))
    if (isFreeForm(config_, name)) return true;
  return false;
}

template <int D>
bool Builder<D>::meshBodyGiven() const {
  for (const auto& name : config_.namesOf("body")) {
    const ConfigEntry* e = config_.find("body." + name, "shape");
    if (e && e->value == "mesh") return true;
  }
  return false;
}

template <int D>
void Builder<D>::fillFreeFormBody() {
  const auto names = config_.namesOf("body");
  const auto given = std::find_if(names.begin(), names.end(),
                                  [&](const std::string& n) { return isFreeForm(config_, n); });
  const std::string name = *given;
  for (const auto& other : names)
    if (other != name)
      throw InputError(config_.where("body." + other, "shape"), "body." + other, "shape",
                       "[body." + name +
                           "] is read from a file (shape = particles or mesh) and must be the "
                           "scene's only body: join the parts in the CAD model or the file");
  if (const auto holes = config_.namesOf("hole"); !holes.empty())
    throw InputError(config_.where("hole." + holes[0], ""), "hole." + holes[0], "",
                     "a hole removes lattice points, and [body." + name +
                         "] is read from a file: cut the hole in the CAD model or the file");
  SectionReader r(config_, "body." + name);
  const std::string kind = r.word("shape", std::nullopt, kFreeFormShapes);
  const std::filesystem::path file = sceneRelative(config_, r.word("file"));
  std::vector<Vec<D>> X;
  std::vector<double> V;
  // A mesh's nodes carry their hats' quadrature moments (GmshBody.hpp); particle files keep
  // the lattice cells' (none given).
  std::vector<Vec<D>> offset;
  std::vector<Mat<D>> spread;
  std::vector<Vec<D>> boundary;  // a_I of the whole boundary (mesh bodies)
  std::vector<Mat<D>> moment;    // b_I (the linear-stress constraint)
  std::map<std::string, SurfacePatch<D>> surfaces;
  std::map<std::string, std::vector<Index>> volumes;
  std::string what;
  if (kind == "particles") {
    try {
      auto set = readParticleFile<D>(file);
      X = std::move(set.position);
      V = std::move(set.volume);
    } catch (const ParticleFileError& e) {
      throw r.error("file", e.what());
    }
    what = "particles from " + file.string();
    setup_.coarsenable = false;
    particleFile_ = true;
  } else {
    const double size = r.has("size") ? r.positive("size") : setup_.dx;
    setup_.coarsenable = !r.has("size");
    MeshOptions options;
    if constexpr (D == 2) options.recombine = r.flag("recombine", true);
    MeshedBody<D> mesh;
    try {
      mesh = meshBody<D>(file.string(), size, options);
    } catch (const GeometryError& e) {
      throw r.error("file", e.what());
    }
    if (integrationConstraint_)
      boundary = boundaryAreaVectors<D>(mesh.position, mesh.cellStart, mesh.cellNode,
                                        integrationLinear_ ? &moment : nullptr);
    X = std::move(mesh.position);
    V = std::move(mesh.volume);
    offset = std::move(mesh.offset);
    spread = std::move(mesh.spread);
    for (auto& [group, s] : mesh.surfaces)
      surfaces.emplace(group, surfacePatch<D>(s));
    volumes = std::move(mesh.volumes);
    what = "mesh of " + file.string() + " at size " + fmt(size);
    if (std::isfinite(mesh.exactMeasure))
      what += ", volume " + fmt(mesh.measure) + " (the CAD model's " + fmt(mesh.exactMeasure) + ")";
  }
  const std::uint16_t material = materialIndex(r);
  r.finish();
  if (X.size() > maxParticles_)
    throw r.error("file", std::to_string(X.size()) +
                              " particles, more than [scene] max_particles = " +
                              std::to_string(maxParticles_));
  if (kind == "particles") chooseSupport(X, V);
  refuseOverlap(r, X, V, kind == "particles" ? "the file's particles" : "the mesh's volumes");

  // Numbered with the longest axis slowest, as lattice bodies are (LocalityOrder.hpp); the
  // surfaces' and volumes' particle lists follow the new numbers.
  const auto axes = localityAxes<D>(X);
  std::vector<Index> order(X.size());
  std::iota(order.begin(), order.end(), Index(0));
  std::sort(order.begin(), order.end(), [&](Index i, Index j) {
    for (int a : axes)
      if (X[i][a] != X[j][a]) return X[i][a] < X[j][a];
    return false;
  });
  std::vector<Index> newIndex(X.size());
  for (std::size_t k = 0; k < order.size(); ++k)
    newIndex[order[k]] = static_cast<Index>(k);
  auto& p = setup_.scene.particles;
  const double rho = density(setup_.scene.materials[material]);
  double total = 0.0;
  if (!offset.empty() && p.quadratureOffset.empty())  // particles before the body: lattice cells
    for (Index j = 0; j < p.size(); ++j) {
      p.quadratureOffset.push_back(Vec<D>::Zero());
      p.quadratureSpread.push_back(latticeSpread<D>(p.volume[j]));
    }
  for (Index i : order) {
    p.add(X[i], V[i], rho * V[i], material);
    if (!offset.empty()) {  // (add() gave it a lattice cell's when there were moments before)
      p.quadratureOffset.resize(p.size());
      p.quadratureSpread.resize(p.size());
      p.quadratureOffset.back() = offset[i];
      p.quadratureSpread.back() = spread[i];
    }
    if (!boundary.empty()) {  // the only body: every particle has its a_I
      p.boundaryArea.resize(p.size());
      p.boundaryArea.back() = boundary[i];
      if (!moment.empty()) {
        p.boundaryMoment.resize(p.size());
        p.boundaryMoment.back() = moment[i];
      }
    }
    setup_.body.push_back(0);
    setup_.ghost.push_back(0);
    total += V[i];
  }
  bodyCount_ = p.size();
  for (auto& [group, patch] : surfaces) {
    std::vector<std::size_t> byNew(patch.particles.size());
    std::iota(byNew.begin(), byNew.end(), std::size_t(0));
    std::sort(byNew.begin(), byNew.end(), [&](std::size_t a, std::size_t b) {
      return newIndex[patch.particles[a]] < newIndex[patch.particles[b]];
    });
    SurfacePatch<D> renumbered;
    renumbered.measure = patch.measure;
    for (std::size_t k : byNew) {
      renumbered.particles.push_back(newIndex[patch.particles[k]]);
      renumbered.area.push_back(patch.area[k]);
      renumbered.areaVector.push_back(patch.areaVector[k]);
    }
    for (auto facet : patch.facets) {
      for (auto& node : facet)
        node = newIndex[node];
      renumbered.facets.push_back(facet);
    }
    setup_.surfaces.emplace(group, std::move(renumbered));
  }
  for (auto& [group, list] : volumes) {
    for (auto& i : list)
      i = newIndex[i];
    std::sort(list.begin(), list.end());
  }
  setup_.freeForm = true;
  setup_.bodyNames.push_back(name);
  std::vector<Index> all(bodyCount_);
  std::iota(all.begin(), all.end(), Index(0));
  setup_.regions["all"] = all;
  for (auto& [group, list] : volumes)
    freeFormVolumes_[group] = std::move(list);

  std::string groups;
  for (const auto& [group, patch] : setup_.surfaces)
    groups += (groups.empty() ? "" : ", ") + group + " (" + std::to_string(patch.particles.size()) +
              " particles, area " + fmt(patch.measure) + ")";
  setup_.conditions.push_back("body." + name + ": " + what + ", " + std::to_string(bodyCount_) +
                              " particles, volume " + fmt(total) +
                              (groups.empty() ? "" : "; surfaces " + groups));
  // The kernel's support is [kernel] support times [scene] dx: a dx far from the particles'
  // own spacing gives neighbourhoods far too small or too large.
  const double spacing = std::pow(total / double(bodyCount_), 1.0 / D);
  if (spacing < 0.5 * setup_.dx || spacing > 2.0 * setup_.dx)
    setup_.warnings.push_back(config_.where("scene", "dx") + ": [scene] dx = " + fmt(setup_.dx) +
                              " but the particles of [body." + name +
                              "] are spaced about (V / N)^(1/d) = " + fmt(spacing) +
                              " apart: the kernel support is [kernel] support x dx; set dx near "
                              "the particles' spacing");
}

// A particle file off a lattice needs a wider support for the quadratic fit across its faces
// (ParticleSetChecks.hpp), unless [kernel] support says otherwise.
template <int D>
void Builder<D>::chooseSupport(const std::vector<Vec<D>>& X, const std::vector<double>& V) {
  if (config_.find("kernel", "support") || onCellCentredLattice<D>(X, V)) return;
  supportRatio_ = kOffLatticeSupportRatio;
  setup_.scene.supportRadius = supportRatio_ * setup_.dx;
  setup_.conditions.push_back("kernel: support " + fmt(supportRatio_) +
                              " dx (the particles are not on a lattice: the quadratic fit "
                              "needs a second layer of neighbours across each face)");
}

// Particles whose volumes count twice somewhere (two overlapping volumes of a CAD model, two
// clouds in one file) are refused, the densest one named; so are two particles on top of each
// other.
template <int D>
void Builder<D>::refuseOverlap(SectionReader& r, const std::vector<Vec<D>>& X,
                               const std::vector<double>& V, const std::string& what) {
  // One neighbour search for both checks (the set-up builds the body's own lists later).
  const Kernel<D> kernel(setup_.scene.kernel, setup_.scene.supportRadius);
  const NeighbourList nb = buildNeighbourList<D>(X, kernel.supportRadius());
  const DensityPeak peak = densityPeak<D>(X, V, kernel, nb);
  if (peak.density > kOverlapDensity)
    throw r.error("file",
                  what + " overlap: near particle (numbered from 0 as read) " +
                      std::to_string(peak.particle) + " at " + fmt<D>(X[peak.particle]) +
                      " the kernel-weighted sum of the volumes is " + fmt(peak.density) +
                      " (about 1 where the particles tile the body, 2 where " +
                      "two parts cover the same space); its nearest particle, " +
                      std::to_string(peak.closest) + " at " + fmt<D>(X[peak.closest]) + ", is " +
                      fmt(peak.distance) +
                      " away. Fuse overlapping volumes in the CAD model (a boolean union), remove "
                      "the doubled particles from the file, or set [scene] dx near the particles' "
                      "spacing");
  const ClosestPair pair = closestPair<D>(X, V, nb);
  if (pair.ratio < kCloseRatio)
    throw r.error("file",
                  "particles (numbered from 0 as read) " + std::to_string(pair.first) + " at " +
                      fmt<D>(X[pair.first]) + " and " + std::to_string(pair.second) + " at " +
                      fmt<D>(X[pair.second]) + " are " +
                      fmt(pair.ratio * std::pow(std::min(V[pair.first], V[pair.second]), 1.0 / D)) +
                      " apart, " + fmt(pair.ratio) + " of their spacing V^(1/d) (at least " +
                      fmt(kCloseRatio) +
                      " expected): the kernel cannot tell them apart; remove one or "
                      "merge their volumes");
}

template <int D>
const SurfacePatch<D>& Builder<D>::namedSurface(SectionReader& r, const std::string& key) {
  std::vector<std::string> known;
  for (const auto& [name, patch] : setup_.surfaces)
    known.push_back(name);
  if (!setup_.freeForm || known.empty())
    throw r.error(key,
                  "the scene has no named surface: surfaces are the physical groups of "
                  "dimension " +
                      std::to_string(D - 1) +
                      " of a body meshed from a CAD or mesh file (shape = mesh)");
  return setup_.surfaces.at(r.word(key, std::nullopt, known));
}

// [kernel] integration_constraint needs the boundary's area vectors, which only a body meshed
// from a CAD or mesh file has.
template <int D>
void Builder<D>::checkIntegrationConstraint() {
  if (!integrationConstraint_ || !setup_.scene.particles.boundaryArea.empty()) return;
  throw InputError(config_.where("kernel", "integration_constraint"), "kernel",
                   "integration_constraint",
                   "needs the body's boundary, which a body meshed from a CAD or mesh file "
                   "(shape = mesh) has; lattice bodies and particle files have none");
}

template bool Builder<2>::freeFormBodyGiven() const;
template bool Builder<2>::meshBodyGiven() const;
template void Builder<2>::fillFreeFormBody();
template void Builder<2>::checkIntegrationConstraint();
template const SurfacePatch<2>& Builder<2>::namedSurface(SectionReader&, const std::string&);
template void Builder<2>::chooseSupport(const std::vector<Vec<2>>&, const std::vector<double>&);
template void Builder<2>::refuseOverlap(SectionReader&, const std::vector<Vec<2>>&,
                                        const std::vector<double>&, const std::string&);
template void Builder<3>::chooseSupport(const std::vector<Vec<3>>&, const std::vector<double>&);
template void Builder<3>::refuseOverlap(SectionReader&, const std::vector<Vec<3>>&,
                                        const std::vector<double>&, const std::string&);
template bool Builder<3>::freeFormBodyGiven() const;
template bool Builder<3>::meshBodyGiven() const;
template void Builder<3>::fillFreeFormBody();
template void Builder<3>::checkIntegrationConstraint();
template const SurfacePatch<3>& Builder<3>::namedSurface(SectionReader&, const std::string&);

}  // namespace tlsph::scene_build
