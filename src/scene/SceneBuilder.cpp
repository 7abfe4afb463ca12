#include "scene/SceneBuilder.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <map>
#include <memory>
#include <numbers>
#include <random>
#include <set>
#include <sstream>
#include <stdexcept>

#include "geometry/LatticeFill.hpp"
#include "geometry/LocalityOrder.hpp"
#include "geometry/Shape.hpp"
#include "scene/SectionReader.hpp"
#include "method/Kernel.hpp"

namespace tlsph {

namespace {

const std::vector<std::string> kFieldNames = {"displacement",    "velocity",      "J",
                                              "von_mises",       "cauchy_stress", "first_piola",
                                              "hourglass_error", "flags"};

std::string fmt(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

template <int D>
std::string fmt(const Vec<D>& v) {
  std::ostringstream s;
  s << "(" << v.transpose() << ")";
  return s.str();
}

// The `axis` of a rotation, normalised: required in 3D; in 2D the rotation is about z, so the
// key may be left out or must be along z (-z reverses the sense).
template <int D>
Vec3 rotationAxis(SectionReader& r) {
  if constexpr (D == 2) {
    if (!r.has("axis")) return Vec3::UnitZ();
    const auto v = r.numbers("axis");
    const Vec3 a = v.size() == 3 ? Vec3(v[0], v[1], v[2]) : Vec3::Zero();
    if (a.isZero() || a.head<2>().norm() > 1e-12 * a.norm())
      throw r.error("axis", "a 2D rotation is about z: give 0 0 1 or 0 0 -1, or leave the key out");
    return a.z() > 0 ? Vec3::UnitZ() : Vec3(-Vec3::UnitZ());
  } else {
    const Vec3 a = r.vector<3>("axis");
    if (!(a.norm() > 0.0)) throw r.error("axis", "must not be zero");
    return a.normalized();
  }
}

template <int D>
std::string rotationText(const Vec3& axis, const Vec<D>& point, double rate) {
  std::string s = "rate " + fmt(rate) + " rad/s about ";
  if constexpr (D == 2) {
    s += axis.z() > 0 ? "z" : "-z";
  } else {
    s += "axis " + fmt<3>(axis);
  }
  return s + " through " + fmt<D>(point);
}

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

template <int D>
class Builder {
 public:
  explicit Builder(const Config& config) : config_(config) {}

  SceneSetup<D> build() {
    rejectUnknownSections();
    readSceneSection();
    readMaterials();
    readDiscretisation();
    fillBodies();
    readRegions();
    addClamps();
    readPrescriptions();
    readLoads();
    readInitialConditions();
    readTimeAndDamping();
    readOutput();
    readCheckpoint();
    readGuard();
    readProbes();
    return std::move(setup_);
  }

 private:
  void readSceneSection() {
    SectionReader r(config_, "scene");
    r.allow({"dimension"});
    setup_.sourceFile = config_.origin();
    setup_.name = r.word("name", std::filesystem::path(config_.origin()).stem().string());
    if (setup_.name.empty() || setup_.name.find_first_of("/\\") != std::string::npos)
      throw r.error("name", "must be a file name without '/' (it names the output files), got '" +
                                setup_.name + "'");
    setup_.dx = r.positive("dx");
    if (!latticeSpacingUsable(setup_.dx))
      throw r.error("dx", "must lie between 2^-960 and 2^960 (about 1e-289 and 1e289), got " +
                              fmt(setup_.dx));
    const long most = r.integer("max_particles", 5'000'000);
    if (most < 1) throw r.error("max_particles", "must be at least 1, got " + fmt(double(most)));
    maxParticles_ = static_cast<std::size_t>(most);
    r.finish();
  }

  void readMaterials() {
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
  void warnNearlyIncompressible() {
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

  void readDiscretisation() {
    SectionReader k(config_, "kernel");
    try {
      setup_.scene.kernel =
          parseKernelType(k.word("type", "wendland-c2", {"wendland-c2", "cubic-bspline"}));
    } catch (const std::invalid_argument& e) {
      throw k.error("type", e.what());
    }
    const double ratio = k.positive("support", 2.1);
    if (ratio < 1.5 || ratio > 5.0)
      throw k.error("support", "H/dx = " + fmt(ratio) + " is outside the useful range [1.5, 5]");
    supportRatio_ = ratio;
    setup_.scene.gradientCorrection =
        parseGradientCorrection(k.word("correction", "quadratic", {"linear", "quadratic"}));
    setup_.scene.supportRadius = ratio * setup_.dx;
    // nodal = the one-point sum_I V_I psi(F_I); taylor adds its second-order term
    // (TaylorQuadrature.hpp), the default where it can run: it needs the quadratic fit.
    const bool quadratic = setup_.scene.gradientCorrection == GradientCorrection::Quadratic;
    setup_.scene.quadrature =
        parseQuadrature(k.word("quadrature", quadratic ? "taylor" : "nodal", {"nodal", "taylor"}));
    if (setup_.scene.quadrature == Quadrature::Taylor && !quadratic)
      throw k.error("quadrature",
                    "taylor needs correction = quadratic (its second derivatives come from the "
                    "quadratic fit)");
    if (setup_.scene.quadrature == Quadrature::Taylor) warnNearlyIncompressible();
    k.finish();
    SectionReader h(config_, "hourglass");
    setup_.scene.hourglassCoefficient = h.nonNegative("alpha", 10.0);
    setup_.scene.hourglassForm =
        parseHourglassForm(h.word("form", "energy", {"energy", "ganzenmueller"}));
    setup_.scene.hourglassGradient =
        parseHourglassGradient(h.word("gradient", "corrected", {"corrected", "linear"}));
    h.finish();
    SectionReader v(config_, "artificial_viscosity");
    setup_.scene.viscosity.linear = v.nonNegative("linear", 0.0);
    setup_.scene.viscosity.quadratic = v.nonNegative("quadratic", 0.0);
    v.finish();
  }

  void fillBodies() {
    const auto names = config_.namesOf("body");
    if (names.empty())
      throw InputError(config_.origin(), "body.NAME", "",
                       "the scene needs at least one [body.NAME] section");
    std::vector<Shape<D>> shapes;
    std::vector<std::uint16_t> materialOfBody;
    for (const auto& name : names) {
      SectionReader r(config_, "body." + name);
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
                       anyPoint
                           ? "the body holds no particle: each of its lattice points at dx = " +
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
  void checkLatticeRange(SectionReader& r, const Shape<D>& shape) {
    const auto box = bounds(shape);
    if (!box) return;
    for (int a = 0; a < D; ++a)
      if (!withinLatticeReach(std::max(std::abs(box->min()[a]), std::abs(box->max()[a])),
                              setup_.dx))
        throw r.error("shape",
                      std::string("the body reaches ") + "xyz"[a] + " = " +
                          fmt(std::abs(box->min()[a]) > std::abs(box->max()[a]) ? box->min()[a]
                                                                                : box->max()[a]) +
                          ", too many lattice spacings (dx = " + fmt(setup_.dx) +
                          ") from the origin (at most 2^20 = 1048576)");
  }

  std::uint16_t materialIndex(SectionReader& r) {
    const auto& names = setup_.materialNames;
    if (!r.has("material")) {
      if (names.size() == 1) return 0;
      throw r.error("material", "missing: the scene has several materials, name one");
    }
    const std::string m = r.word("material", std::nullopt, names);
    return static_cast<std::uint16_t>(std::find(names.begin(), names.end(), m) - names.begin());
  }

  void readRegions() {
    // A region selects the body particles whose cells it holds, decided where the fill decided
    // which cells are particles (testedPoint: (n + 1/2) dx as evaluated in double), so that a
    // region face through cell centres selects what it selected before the exact grid.
    const auto& X = setup_.scene.particles.referencePosition;
    std::vector<Vec<D>> bodyX(static_cast<std::size_t>(bodyCount_));
    for (Index i = 0; i < bodyCount_; ++i)
      bodyX[i] = testedPoint<D>(lattice_, X[i], setup_.dx);
    for (const auto& name : config_.namesOf("region")) {
      SectionReader r(config_, "region." + name);
      if (name == "all") throw r.error("", "'all' is a built-in region (every body particle)");
      const Shape<D> shape = readShape<D>(r, true);
      r.finish();
      auto selected = select(shape, bodyX);
      if (selected.empty())
        throw r.error("shape",
                      "the region selects no particle (particles sit at cell centres "
                      "(n + 1/2) dx; make the region at least one dx thick)");
      setup_.regions[name] = std::move(selected);
    }
  }

  const std::vector<Index>& region(SectionReader& r, const std::string& key = "region") {
    std::vector<std::string> known;
    for (const auto& [name, list] : setup_.regions)
      known.push_back(name);
    const std::string name = r.word(key, "all", known);
    return setup_.regions.at(name);
  }

  // The body particle at lattice point X (-1 if none): body particles sit at cell centres.
  Index latticeParticle(const Vec<D>& X) {
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

  static std::vector<std::string> faceNames() {
    std::vector<std::string> faces = {"x-", "x+", "y-", "y+"};
    if (D == 3) faces.insert(faces.end(), {"z-", "z+"});
    return faces;
  }

  // The bodies' bounding box (body particles' reference positions).
  const Eigen::AlignedBox<double, D>& bodyBox() {
    if (bodyBox_.isEmpty())
      for (Index i = 0; i < bodyCount_; ++i)
        bodyBox_.extend(setup_.scene.particles.referencePosition[i]);
    return bodyBox_;
  }

  // Whether body particle i lies in the layer of particles at the bodies' extreme along `face`
  // ("x-", ..., "z+"): the particles a clamp mirrors and a face load acts on.
  bool onBoundingFace(Index i, const std::string& face) {
    const int axis = face[0] - 'x';
    const double edge = face[1] == '-' ? bodyBox().min()[axis] : bodyBox().max()[axis];
    return std::abs(setup_.scene.particles.referencePosition[i][axis] - edge) <= 0.25 * setup_.dx;
  }

  // A traction acts on the area dx^(d-1) of each particle it is given to, so a region that
  // holds particles below the surface applies it more than once: say so.
  void warnInteriorTraction(const Load<D>& load, const std::string& regionName) {
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

  void addClamps() {
    const int layersNeeded = static_cast<int>(std::ceil(supportRatio_ - 1e-9));
    auto& p = setup_.scene.particles;
    const auto& X = p.referencePosition;
    std::set<std::string> facesUsed;
    for (const auto& name : config_.namesOf("clamp")) {
      SectionReader r(config_, "clamp." + name);
      const std::string face = r.word("face", std::nullopt, faceNames());
      if (!facesUsed.insert(face).second)
        throw r.error("face", "face " + face + " is clamped twice");
      const std::string method =
          r.word("method", "mirror", {"mirror", "mirror-quadratic", "fixed"});
      const long layers = r.integer("layers", layersNeeded);
      if (layers < layersNeeded)
        throw r.error("layers", std::to_string(layers) +
                                    " ghost layers do not fill the kernel support "
                                    "(H/dx = " +
                                    fmt(supportRatio_) + " needs " + std::to_string(layersNeeded) +
                                    ")");
      Prescription<D> clamp;
      clamp.name = "clamp." + name;
      const std::string motion = readMotion(r, clamp);
      r.finish();
      // The ghosts count against [scene] max_particles too (a mistyped `layers`).
      Index onFace = 0;
      for (Index i = 0; i < bodyCount_; ++i)
        onFace += onBoundingFace(i, face) ? 1 : 0;
      const double total = double(p.size()) + double(onFace) * double(layers);
      if (total > double(maxParticles_))
        throw r.error(
            "layers",
            std::to_string(layers) + " ghost layers of the " + std::to_string(onFace) +
                " particles on face " + face + " make " + fmt(total) +
                " particles, more than [scene] max_particles = " + std::to_string(maxParticles_));
      const std::string holds = method == "fixed"
                                    ? "holds face " + face
                                    : "mirrors the first " + std::to_string(layers) +
                                          " body layers behind face " + face + " with its ghosts";
      const int axis = face[0] - 'x';
      const double sign = face[1] == '-' ? -1.0 : 1.0;
      const bool mirror = method != "fixed";
      const bool quadratic = method == "mirror-quadratic";
      const int rule = static_cast<int>(setup_.scene.prescriptions.size());
      const double V = std::pow(setup_.dx, D);
      Index ghosts = 0, fixedFallback = 0, oddFallback = 0;
      Vec<D> thinAt = Vec<D>::Zero();
      for (Index i = 0; i < bodyCount_; ++i) {
        if (!onBoundingFace(i, face)) continue;
        if (!mirror) clampHeld_.emplace(i, std::pair{name, holds});
        for (long k = 1; k <= layers; ++k) {
          // Ghost layer k is the lattice's cell k spacings outside X_i, exact on its grid.
          const LatticeIndex cell = lattice_[axis].index(X[i][axis]) + (sign > 0 ? k : -k);
          if (!lattice_[axis].holds(cell))
            throw r.error("layers", std::to_string(layers) +
                                        " ghost layers reach beyond the lattice's range");
          Vec<D> G = X[i];
          G[axis] = lattice_[axis].coordinate(cell);
          // Ghost layer k mirrors body layer k across the face (half a spacing outside X_i);
          // the quadratic extrapolation also uses body layer k + 1 (MirrorGhost). Where the
          // body is too thin behind the face (a wedge's tip), the ghost falls back to the
          // odd reflection, or, with no body particle to mirror at all, is held as a fixed
          // ghost that follows the clamp's motion.
          MirrorGhost m;
          bool mirrored = false;
          if (mirror) {
            auto behind = [&](long l) {
              Vec<D> M = X[i];
              M[axis] -= sign * (l - 1) * setup_.dx;
              return latticeParticle(M);
            };
            m.mirror = behind(k);
            mirrored = m.mirror >= 0;
            if (mirrored) clampHeld_.emplace(m.mirror, std::pair{name, holds});
            if (mirrored && quadratic) {
              m.second = behind(k + 1);
              if (m.second >= 0) clampHeld_.emplace(m.second, std::pair{name, holds});
              if (m.second >= 0) {
                // Lagrange extrapolation through u_p on the face, body layers k and k + 1.
                m.w1 = -2.0 * k;
                m.w2 = (2.0 * k - 1.0) * (2.0 * k - 1.0) / (2.0 * k + 1.0);
              } else {
                ++oddFallback;
              }
            }
            if (!mirrored && fixedFallback++ == 0) thinAt = X[i];
            m.motion = rule;
          }
          const std::uint16_t mat = p.material[i];
          const Index g = p.add(G, V, density(setup_.scene.materials[mat]) * V, mat,
                                mirrored ? Motion::Mirrored : Motion::Prescribed);
          if (mirrored) {
            m.ghost = g;
            setup_.scene.mirrorGhosts.push_back(m);
          } else {
            clamp.particles.push_back(g);
          }
          setup_.body.push_back(setup_.body[i]);
          setup_.ghost.push_back(1);
          ++ghosts;
        }
      }
      setup_.conditions.push_back(
          "clamp." + name + ": face " + face + ", " + method + ", " +
          (motion == "fixed" ? "" : motion + " " + motionText(clamp) + ", ") +
          std::to_string(layers) + " ghost layers, " + std::to_string(ghosts) + " ghost particles");
      if (fixedFallback > 0)
        setup_.warnings.push_back(
            config_.where("clamp." + name, "method") + ": [clamp." + name + "] " +
            std::to_string(fixedFallback) + " of the " + std::to_string(ghosts) +
            " ghosts have no body particle to mirror (the body is thinner than " +
            std::to_string(layers) + " layers behind face " + face + ", e.g. behind " +
            fmt<D>(thinAt) + "); they are held as fixed ghosts (method = fixed there), which " +
            "puts u = 0 dx/2 outside the face at those points");
      if (oddFallback > 0)
        setup_.warnings.push_back(config_.where("clamp." + name, "method") + ": [clamp." + name +
                                  "] " + std::to_string(oddFallback) +
                                  " ghosts have no second body layer behind their mirror "
                                  "particle; they take the odd reflection (method = mirror)");
      // A mirrored clamp's rule holds its fixed-ghost fallbacks only: the other ghosts follow
      // it by reflection.
      setup_.scene.prescriptions.push_back(std::move(clamp));
    }
  }

  // The `motion` of a prescription or a clamp and its keys; returns the motion's name.
  std::string readMotion(SectionReader& r, Prescription<D>& rule) {
    const std::string motion =
        r.word("motion", "fixed", {"fixed", "velocity", "displacement", "rotation"});
    rule.motion = motion == "fixed"          ? PrescribedMotion::Fixed
                  : motion == "velocity"     ? PrescribedMotion::Velocity
                  : motion == "displacement" ? PrescribedMotion::Displacement
                                             : PrescribedMotion::Rotation;
    if (rule.motion == PrescribedMotion::Rotation) {
      // Rigid rotation about the axis through `point` at `rate` rad/s (times the ramp).
      rule.axis = rotationAxis<D>(r);
      rule.point = r.vector<D>("point");
      rule.rate = r.number("rate");
    } else if (rule.motion != PrescribedMotion::Fixed) {
      rule.value = r.vector<D>("value");
    }
    rule.ramp.duration = r.nonNegative("ramp", 0.0);
    if (rule.motion != PrescribedMotion::Rotation) r.allow({"value"});
    return motion;
  }

  static std::string motionText(const Prescription<D>& rule) {
    return rule.motion == PrescribedMotion::Fixed ? ""
           : rule.motion == PrescribedMotion::Rotation
               ? rotationText<D>(rule.axis, rule.point, rule.rate)
               : fmt<D>(rule.value);
  }

  void readPrescriptions() {
    auto& p = setup_.scene.particles;
    for (const auto& name : config_.namesOf("prescribe")) {
      SectionReader r(config_, "prescribe." + name);
      Prescription<D> rule;
      rule.name = "prescribe." + name;
      rule.particles = region(r);
      const std::string motion = readMotion(r, rule);
      r.finish();
      for (Index i : rule.particles) {
        if (const auto c = clampHeld_.find(i); c != clampHeld_.end())
          throw r.error("region", "particle " + std::to_string(i) + " at " +
                                      fmt<D>(p.referencePosition[i]) + " is held by [clamp." +
                                      c->second.first + "], which " + c->second.second +
                                      ": a particle cannot be both clamped and prescribed; keep "
                                      "the region clear of them, or move the face with the "
                                      "clamp's own motion");
        if (p.motion[i] == Motion::Prescribed)
          throw r.error("region", "particle " + std::to_string(i) + " at " +
                                      fmt<D>(p.referencePosition[i]) +
                                      " is already prescribed by another condition");
        p.motion[i] = Motion::Prescribed;
      }
      const std::string what = rule.motion == PrescribedMotion::Fixed ? "" : motionText(rule) + " ";
      setup_.conditions.push_back(rule.name + ": " + motion + " " + what + "on " +
                                  std::to_string(rule.particles.size()) + " particles");
      setup_.scene.prescriptions.push_back(std::move(rule));
    }
  }

  void readLoads() {
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
      if (r.has("face")) {
        // The surface layer of the bodies' face (as for clamps), within the region if given.
        const std::string face = r.word("face", std::nullopt, faceNames());
        std::vector<Index> onFace;
        for (Index i : load.particles)
          if (onBoundingFace(i, face)) onFace.push_back(i);
        if (onFace.empty())
          throw r.error("face", "the region '" + (regionName.empty() ? "all" : regionName) +
                                    "' has no particle on face " + face +
                                    " (the layer of particles at the bodies' extreme along " +
                                    face + ")");
        load.particles = std::move(onFace);
        where = " on face " + face + where;
      }
      const std::string type = r.word("type", std::nullopt, {"traction", "force"});
      const Vec<D> value = r.vector<D>("value");
      load.ramp.duration = r.nonNegative("ramp", 0.0);
      r.finish();
      if (type == "traction") warnInteriorTraction(load, regionName);
      double volume = 0.0;
      for (Index i : load.particles)
        volume += p.volume[i];
      for (Index i : load.particles) {
        // (6.76): a traction acts on the area a_I = V_I^((d-1)/d) of each surface particle.
        const double share =
            type == "traction" ? std::pow(p.volume[i], (D - 1.0) / D) : p.volume[i] / volume;
        load.force.push_back(share * value);
      }
      setup_.conditions.push_back(load.name + ": " + type + " " + fmt<D>(value) + " on " +
                                  std::to_string(load.particles.size()) + " particles" + where);
      setup_.scene.loads.push_back(std::move(load));
    }
  }

  void readInitialConditions() {
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
          amplitude = r.number("amplitude_over_c0") *
                      std::sqrt(elasticConstants(m).bulkModulus / density(m));
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
      r.allow({"velocity", "amplitude", "amplitude_over_c0", "axis", "direction", "origin",
               "length", "kL", "point", "rate", "seed"});
      r.finish();
    }
  }

  void readTimeAndDamping() {
    SectionReader d(config_, "damping");
    setup_.scene.damping.viscous = d.nonNegative("viscous", 0.0);
    setup_.scene.damping.kinetic = d.flag("kinetic", false);
    d.finish();
    SectionReader s(config_, "static");
    setup_.run.quasiStatic = s.flag("enabled", config_.hasSection("static"));
    setup_.run.tolerance = s.positive("tolerance", 1e-5);
    setup_.run.checkEvery = std::max(1L, s.integer("check_every", 50));
    const bool newton = s.word("solver", "damped", {"damped", "newton"}) == "newton";
    setup_.run.staticSolver =
        newton ? RunSettings::StaticSolver::Newton : RunSettings::StaticSolver::Damped;
    auto& n = setup_.run.newton;
    n.tolerance = setup_.run.tolerance;
    const long loadSteps = s.integer("load_steps", 1);
    if (loadSteps < 1 || loadSteps > 100000)
      throw s.error("load_steps",
                    "must be between 1 and 100000, got " + config_.get("static", "load_steps"));
    n.loadSteps = static_cast<int>(loadSteps);
    const long iterations = s.integer("max_iterations", 30);
    if (iterations < 1 || iterations > 100000)
      throw s.error("max_iterations",
                    "must be between 1 and 100000, got " + config_.get("static", "max_iterations"));
    n.maxIterations = static_cast<int>(iterations);
    const std::string preconditioner =
        s.word("preconditioner", "auto", {"auto", "cholesky", "multigrid"});
    n.preconditioner = preconditioner == "cholesky"    ? NewtonPreconditioner::Cholesky
                       : preconditioner == "multigrid" ? NewtonPreconditioner::Multigrid
                                                       : NewtonPreconditioner::Auto;
    s.finish();
    SectionReader t(config_, "time");
    setup_.solver.cfl = t.positive("cfl", kDefaultCfl);
    setup_.solver.timeStep = t.nonNegative("dt", 0.0);
    // A Newton static run has no time to march; `end` only scales the default output interval.
    setup_.run.endTime =
        newton && setup_.run.quasiStatic ? t.positive("end", 1.0) : t.positive("end");
    setup_.run.maxSteps = t.integer("max_steps", 0);
    t.finish();
    if (setup_.run.quasiStatic && newton && setup_.scene.hourglassCoefficient != 0.0 &&
        setup_.scene.hourglassForm != HourglassForm::Energy)
      throw InputError(config_.where("static", "solver"), "static", "solver",
                       "solver = newton needs the hourglass penalty's energy form ([hourglass] "
                       "form = energy): the textbook force (6.80)-(6.81) is not the gradient of "
                       "an energy and has no symmetric tangent");
    if (setup_.run.quasiStatic) {
      if (!newton && !setup_.scene.damping.any())
        throw InputError(config_.where("static", "enabled"), "static", "enabled",
                         "a static run needs damping: set [damping] kinetic = true or viscous > 0, "
                         "or solve it with [static] solver = newton");
      if (setup_.scene.prescriptions.empty() && setup_.scene.mirrorGhosts.empty())
        throw InputError(config_.where("static", "enabled"), "static", "enabled",
                         "a static run needs the body held: add a [clamp.NAME] or a "
                         "[prescribe.NAME] section, or it drifts away under its loads");
    }
  }

  void readOutput() {
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
  void readCheckpoint() {
    SectionReader c(config_, "checkpoint");
    setup_.checkpoint.everySteps = c.integer("every_steps", 0);
    setup_.checkpoint.everySeconds = c.nonNegative("every_seconds", 600.0);
    setup_.checkpoint.keep = c.integer("keep", 2);
    if (setup_.checkpoint.keep < 1)
      throw c.error("keep", "must be at least 1 (the newest checkpoint), got " +
                                config_.get("checkpoint", "keep"));
    c.finish();
  }

  // The run's stability guards (RunSimulation.hpp), checked every [static] check_every steps.
  void readGuard() {
    SectionReader g(config_, "guard");
    setup_.guard.minJacobian = g.number("min_jacobian", 0.0);
    if (!(setup_.guard.minJacobian >= 0.0 && setup_.guard.minJacobian < 1.0))
      throw g.error("min_jacobian",
                    "must be in [0, 1), got " + config_.get("guard", "min_jacobian"));
    setup_.guard.energyError = g.nonNegative("energy_error", 0.05);
    g.finish();
  }

  void readProbes() {
    const auto& p = setup_.scene.particles;
    const Kernel<D> kernel(setup_.scene.kernel, setup_.scene.supportRadius);
    for (const auto& name : config_.namesOf("probe")) {
      SectionReader r(config_, "probe." + name);
      Probe<D> probe;
      probe.name = name;
      probe.point = r.vector<D>("point");
      probe.method = r.word("method", "nearest", {"nearest", "kernel"}) == "nearest"
                         ? ProbeMethod::Nearest
                         : ProbeMethod::Kernel;
      probe.quantities = r.words("quantities", {"displacement"});
      for (const auto& q : probe.quantities)
        if (q != "displacement" && q != "velocity" && q != "cauchy_stress")
          throw r.error("quantities", "unknown quantity '" + q +
                                          "'; expected displacement, velocity, cauchy_stress");
      r.finish();
      if (probe.method == ProbeMethod::Nearest) {
        // Of equally near particles, the first in the lattice's order (latticeOrderBefore):
        // the choice depends on the particles' places, not on their numbering.
        const auto& X = p.referencePosition;
        auto before = [&](Index i, Index j) {
          const double di = (X[i] - probe.point).squaredNorm(),
                       dj = (X[j] - probe.point).squaredNorm();
          if (di != dj) return di < dj;
          return latticeOrderBefore<D>(X[i], X[j]);
        };
        Index best = 0;
        for (Index i = 1; i < bodyCount_; ++i)
          if (before(i, best)) best = i;
        probe.particles = {best};
        probe.weights = {1.0};
      } else {
        // Shepard-normalised kernel interpolation over the reference neighbourhood; each
        // particle's displacement is carried to the point with its own gradient F - 1, so the
        // probe is exact for linear fields even on the surface (a beam's tip).
        double sum = 0.0;
        for (Index i = 0; i < bodyCount_; ++i) {
          const double w =
              kernel.value((p.referencePosition[i] - probe.point).norm()) * p.volume[i];
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

  void rejectUnknownSections() {
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

  const Config& config_;
  SceneSetup<D> setup_;
  Eigen::AlignedBox<double, D> bodyBox_;
  std::size_t maxParticles_ = 0;
  double supportRatio_ = 2.0;
  Index bodyCount_ = 0;
  std::map<std::array<long, D>, Index> latticeIndex_;  // lattice point -> body particle
  std::array<LatticeAxis, D> lattice_{};               // the bodies' lattice
  // Body particles a clamp holds (its face layer, or the layers its ghosts mirror): the clamp's
  // name and what it does, for the error when a [prescribe] region takes one of them too.
  std::map<Index, std::pair<std::string, std::string>> clampHeld_;
};

}  // namespace

int sceneDimension(const Config& config) {
  SectionReader r(config, "scene");
  const std::string d = r.word("dimension", std::nullopt, {"2", "3"});
  return d == "2" ? 2 : 3;
}

template <int D>
SceneSetup<D> buildScene(const Config& config) {
  SceneSetup<D> setup = Builder<D>(config).build();
  const double dx = setup.dx;
  setup.coarsen = [config, dx](int factor) -> std::unique_ptr<Scene<D>> {
    std::ostringstream spacing;
    spacing << std::setprecision(17) << factor * dx;
    try {
      Config coarse = config.with("scene.dx", spacing.str(), "multigrid coarsening");
      return std::make_unique<Scene<D>>(Builder<D>(coarse).build().scene);
    } catch (const std::exception&) {
      return nullptr;  // too coarse for this geometry: no such level
    }
  };
  return setup;
}

template SceneSetup<2> buildScene<2>(const Config&);
template SceneSetup<3> buildScene<3>(const Config&);

}  // namespace tlsph
