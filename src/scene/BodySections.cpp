// [body.NAME], [hole.NAME], [region.NAME]: the lattice the bodies fill, the particles on it
// and the named sets of them the conditions refer to.
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "geometry/LatticeFill.hpp"
#include "geometry/LocalityOrder.hpp"
#include "scene/Builder.hpp"

namespace tlsph::scene_build {

namespace {

template <int D>
Shape<D> readShape(SectionReader& r, bool allowUnbounded) {
  std::vector<std::string> kinds = {"box", "cylinder", "ball", "polygon"};
  if (allowUnbounded) kinds.push_back("half-space");
  const std::string kind = r.word("shape", std::nullopt, kinds);
  Shape<D> shape;
  if (kind == "box") {
    shape = Box<D>{r.vector<D>("lower"), r.vector<D>("upper")};
  } else if (kind == "cylinder") {
    Cylinder<D> c;
    if constexpr (D == 2) {
      c.start = r.vector<D>("centre");
      c.end = c.start;
    } else {
      c.start = r.vector<D>("start");
      c.end = r.vector<D>("end");
    }
    c.radius = r.positive("radius");
    shape = c;
  } else if (kind == "ball") {
    shape = Ball<D>{r.vector<D>("centre"), r.positive("radius")};
  } else if (kind == "polygon") {
    Polygon<D> p;
    const auto xy = r.numbers("vertices");
    if (xy.size() % 2 != 0 || xy.size() < 6)
      throw r.error("vertices", "expected at least three 'x y' pairs, e.g. 0 0, 1 0, 0 1");
    for (std::size_t k = 0; k < xy.size(); k += 2)
      p.vertices.push_back(Vec<2>(xy[k], xy[k + 1]));
    if constexpr (D == 3) {
      const std::string axis = r.word("axis", "z", {"x", "y", "z"});
      p.axis = axis == "x" ? 0 : axis == "y" ? 1 : 2;
      p.from = r.number("from");
      p.to = r.number("to");
    }
    shape = p;
  } else {
    shape = HalfSpace<D>{r.vector<D>("point"), r.vector<D>("normal")};
  }
  try {
    validate(shape);
  } catch (const std::invalid_argument& e) {
    throw r.error("shape", e.what());
  }
  return shape;
}

}  // namespace

template <int D>
void Builder<D>::fillBodies() {
  const auto names = config_.namesOf("body");
  if (names.empty())
    throw InputError(config_.origin(), "body.NAME", "",
                     "the scene needs at least one [body.NAME] section");
  if (freeFormBodyGiven()) {
    fillFreeFormBody();
    return;
  }
  std::vector<Shape<D>> shapes;
  std::vector<std::uint16_t> materialOfBody;
  for (const auto& name : names) {
    SectionReader r(config_, "body." + name);
    // Listed with the shapes read from files (FreeFormBodies.cpp) for the error's choices.
    r.word("shape", std::nullopt, {"box", "cylinder", "ball", "polygon", "particles", "mesh"});
    shapes.push_back(readShape<D>(r, false));
    materialOfBody.push_back(materialIndex(r));
    r.finish();
    checkLatticeRange(r, shapes.back());
    setup_.bodyNames.push_back(name);
  }
  if (names.size() > 256)  // the output's `body` flag is one byte
    throw InputError(config_.where("body." + names[256], ""), "body." + names[256], "",
                     "a scene holds at most 256 bodies");
  std::vector<Shape<D>> holes;
  for (const auto& name : config_.namesOf("hole")) {
    SectionReader r(config_, "hole." + name);
    holes.push_back(readShape<D>(r, false));
    r.finish();
  }
  std::vector<Vec<D>> points;
  try {
    points = fillLattice<D>(shapes, setup_.dx, Vec<D>::Zero(), maxParticles_);
    lattice_ = latticeAxes<D>(shapes, setup_.dx);  // the ghosts' layers continue it
  } catch (const std::length_error& e) {
    // The geometry's message, in the scene's words.
    std::string what = e.what();
    if (what.rfind("fillLattice: ", 0) == 0) what = what.substr(13);
    if (const auto at = what.find("(maxPoints)"); at != std::string::npos)
      what.replace(at, 11, "([scene] max_particles)");
    throw InputError(config_.where("scene", "dx"), "scene", "dx",
                     what +
                         "; raise [scene] max_particles if the machine has the memory "
                         "(about 2 kB per particle in 3D)");
  } catch (const std::invalid_argument& e) {
    throw InputError(config_.where("scene", "dx"), "scene", "dx", e.what());
  }
  if (points.empty())
    throw InputError(config_.where("body." + names[0], "shape"), "body." + names[0], "shape",
                     "the bodies contain no lattice point at dx = " + fmt(setup_.dx) +
                         " (particles sit at cell centres (n + 1/2) dx); make them larger "
                         "than dx");
  // [hole.NAME]: the lattice points inside a hole belong to no body (decided where the fill
  // decided, testedPoint).
  std::erase_if(points, [&](const Vec<D>& X) {
    const Vec<D> at = testedPoint<D>(lattice_, X, setup_.dx);
    return std::any_of(holes.begin(), holes.end(),
                       [&](const Shape<D>& h) { return contains(h, at); });
  });
  if (points.empty()) {
    const std::string hole = "hole." + config_.namesOf("hole").front();
    throw InputError(config_.where(hole, "shape"), hole, "shape",
                     "the holes remove every particle of the bodies");
  }
  // Numbered with the longest axis slowest (the pair loops' locality, LocalityOrder.hpp).
  sortForLocality<D>(points);
  const double V = std::pow(setup_.dx, D);
  auto& p = setup_.scene.particles;
  for (const auto& X : points) {
    std::size_t b = 0;
    const Vec<D> at = testedPoint<D>(lattice_, X, setup_.dx);
    while (b + 1 < shapes.size() && !contains(shapes[b], at))
      ++b;
    const std::uint16_t m = materialOfBody[b];
    p.add(X, V, density(setup_.scene.materials[m]) * V, m);
    setup_.body.push_back(static_cast<std::uint8_t>(b));
    setup_.ghost.push_back(0);
  }
  bodyCount_ = p.size();
  // A body that holds no particle is a mistake (a shape smaller than dx, or one inside an
  // earlier body or a hole): it would silently be left out.
  std::vector<Index> perBody(names.size(), 0);
  for (const auto b : setup_.body)
    ++perBody[b];
  for (std::size_t b = 0; b < names.size(); ++b) {
    if (perBody[b] > 0) continue;
    const bool anyPoint =
        !fillLattice<D>({shapes[b]}, setup_.dx, Vec<D>::Zero(), maxParticles_).empty();
    throw InputError(config_.where("body." + names[b], "shape"), "body." + names[b], "shape",
                     anyPoint ? "the body holds no particle: each of its lattice points at dx = " +
                                    fmt(setup_.dx) + " lies in an earlier body or in a hole"
                              : "the body holds no lattice point at dx = " + fmt(setup_.dx) +
                                    " (particles sit at cell centres (n + 1/2) dx); make it "
                                    "larger than dx or move it onto the lattice");
  }
  std::vector<Index> all(bodyCount_);
  for (Index i = 0; i < bodyCount_; ++i)
    all[i] = i;
  setup_.regions["all"] = all;
}

// The lattice indices of a body's bounding box must fit in a double's integers: a coordinate
// mistyped by orders of magnitude (or a dx far too small for it) is named here.
template <int D>
void Builder<D>::checkLatticeRange(SectionReader& r, const Shape<D>& shape) {
  const auto box = bounds(shape);
  if (!box) return;
  for (int a = 0; a < D; ++a)
    if (!withinLatticeReach(std::max(std::abs(box->min()[a]), std::abs(box->max()[a])), setup_.dx))
      throw r.error("shape",
                    std::string("the body reaches ") + "xyz"[a] + " = " +
                        fmt(std::abs(box->min()[a]) > std::abs(box->max()[a]) ? box->min()[a]
                                                                              : box->max()[a]) +
                        ", too many lattice spacings (dx = " + fmt(setup_.dx) +
                        ") from the origin (at most 2^20 = 1048576)");
}

template <int D>
void Builder<D>::readRegions() {
  // A region selects the body particles whose cells it holds, decided where the fill decided
  // which cells are particles (testedPoint: (n + 1/2) dx as evaluated in double), so that a
  // region face through cell centres selects what it selected before the exact grid.
  const auto& X = setup_.scene.particles.referencePosition;
  std::vector<Vec<D>> bodyX(static_cast<std::size_t>(bodyCount_));
  for (Index i = 0; i < bodyCount_; ++i)
    bodyX[i] = setup_.freeForm ? X[i] : testedPoint<D>(lattice_, X[i], setup_.dx);
  for (const auto& name : config_.namesOf("region")) {
    SectionReader r(config_, "region." + name);
    if (name == "all") throw r.error("", "'all' is a built-in region (every body particle)");
    // A mesh body's named surface or volume (its physical groups).
    if (r.has("surface")) {
      setup_.regions[name] = namedSurface(r).particles;
      r.finish();
      continue;
    }
    if (r.has("volume")) {
      std::vector<std::string> known;
      for (const auto& [group, list] : freeFormVolumes_)
        known.push_back(group);
      if (known.empty())
        throw r.error("volume",
                      "the scene has no named volume: volumes are the physical groups "
                      "of dimension " +
                          std::to_string(D) +
                          " of a body meshed from a CAD or mesh file (shape = mesh)");
      setup_.regions[name] = freeFormVolumes_.at(r.word("volume", std::nullopt, known));
      r.finish();
      continue;
    }
    const Shape<D> shape = readShape<D>(r, true);
    r.finish();
    auto selected = select(shape, bodyX);
    if (selected.empty())
      throw r.error("shape", setup_.freeForm
                                 ? "the region selects no particle"
                                 : "the region selects no particle (particles sit at cell centres "
                                   "(n + 1/2) dx; make the region at least one dx thick)");
    setup_.regions[name] = std::move(selected);
  }
}

template <int D>
const std::vector<Index>& Builder<D>::region(SectionReader& r, const std::string& key) {
  std::vector<std::string> known;
  for (const auto& [name, list] : setup_.regions)
    known.push_back(name);
  const std::string name = r.word(key, "all", known);
  return setup_.regions.at(name);
}

// The body particle at lattice point X (-1 if none): body particles sit at cell centres.
template <int D>
Index Builder<D>::latticeParticle(const Vec<D>& X) {
  auto key = [&](const Vec<D>& x) {
    std::array<long, D> k;
    for (int a = 0; a < D; ++a)
      k[a] = std::lround(2.0 * x[a] / setup_.dx);
    return k;
  };
  if (latticeIndex_.empty())
    for (Index i = 0; i < bodyCount_; ++i)
      latticeIndex_[key(setup_.scene.particles.referencePosition[i])] = i;
  const auto it = latticeIndex_.find(key(X));
  return it == latticeIndex_.end() ? -1 : it->second;
}

template <int D>
std::vector<std::string> Builder<D>::faceNames() {
  std::vector<std::string> faces = {"x-", "x+", "y-", "y+"};
  if (D == 3) faces.insert(faces.end(), {"z-", "z+"});
  return faces;
}

// The bodies' bounding box (body particles' reference positions).
template <int D>
const Eigen::AlignedBox<double, D>& Builder<D>::bodyBox() {
  if (bodyBox_.isEmpty())
    for (Index i = 0; i < bodyCount_; ++i)
      bodyBox_.extend(setup_.scene.particles.referencePosition[i]);
  return bodyBox_;
}

// Whether body particle i lies in the layer of particles at the bodies' extreme along `face`
// ("x-", ..., "z+"): the particles a clamp mirrors and a face load acts on.
template <int D>
bool Builder<D>::onBoundingFace(Index i, const std::string& face) {
  const int axis = face[0] - 'x';
  const double edge = face[1] == '-' ? bodyBox().min()[axis] : bodyBox().max()[axis];
  return std::abs(setup_.scene.particles.referencePosition[i][axis] - edge) <= 0.25 * setup_.dx;
}

template void Builder<2>::fillBodies();
template void Builder<2>::checkLatticeRange(SectionReader&, const Shape<2>&);
template void Builder<2>::readRegions();
template const std::vector<Index>& Builder<2>::region(SectionReader&, const std::string&);
template Index Builder<2>::latticeParticle(const Vec<2>&);
template std::vector<std::string> Builder<2>::faceNames();
template const Eigen::AlignedBox<double, 2>& Builder<2>::bodyBox();
template bool Builder<2>::onBoundingFace(Index, const std::string&);
template void Builder<3>::fillBodies();
template void Builder<3>::checkLatticeRange(SectionReader&, const Shape<3>&);
template void Builder<3>::readRegions();
template const std::vector<Index>& Builder<3>::region(SectionReader&, const std::string&);
template Index Builder<3>::latticeParticle(const Vec<3>&);
template std::vector<std::string> Builder<3>::faceNames();
template const Eigen::AlignedBox<double, 3>& Builder<3>::bodyBox();
template bool Builder<3>::onBoundingFace(Index, const std::string&);

}  // namespace tlsph::scene_build
