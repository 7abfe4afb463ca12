// The state buildScene carries from one scene-file section to the next, and the steps that read
// them. The steps are defined by section in the *Sections.cpp files of this folder, each
// instantiated there for 2D and 3D; the order in build() matters (a clamp needs the bodies, a
// static run's checks need the clamps and the damping).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "geometry/LatticeGrid.hpp"
#include "geometry/Shape.hpp"
#include "scene/Config.hpp"
#include "scene/SceneSetup.hpp"
#include "scene/SectionReader.hpp"

namespace tlsph::scene_build {

inline std::string fmt(double v) {
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
class Builder {
 public:
  explicit Builder(const Config& config) : config_(config) {}

  SceneSetup<D> build() {
    rejectUnknownSections();
    readSceneSection();
    readMaterials();
    readDiscretisation();
    fillBodies();
    checkIntegrationConstraint();
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
  // [scene] and the section names (SceneBuilder.cpp).
  void rejectUnknownSections();
  void readSceneSection();

  // [material.NAME] (MaterialSections.cpp).
  void readMaterials();
  void warnNearlyIncompressible();
  std::uint16_t materialIndex(SectionReader& r);

  // [kernel], [hourglass], [artificial_viscosity], [damping], [static], [time]
  // (NumericsSections.cpp).
  void readDiscretisation();
  void readTimeAndDamping();
  void checkFreeBodyLoads(bool newton);

  // [body.NAME], [hole.NAME], [region.NAME] and the lattice they make (BodySections.cpp).
  void fillBodies();
  void checkLatticeRange(SectionReader& r, const Shape<D>& shape);
  void readRegions();
  const std::vector<Index>& region(SectionReader& r, const std::string& key = "region");
  Index latticeParticle(const Vec<D>& X);
  static std::vector<std::string> faceNames();
  const Eigen::AlignedBox<double, D>& bodyBox();
  bool onBoundingFace(Index i, const std::string& face);

  // A body read from a particle file or meshed from a CAD or mesh file, the scene's only body
  // (FreeFormBodies.cpp); the named surfaces conditions refer to.
  bool freeFormBodyGiven() const;
  bool meshBodyGiven() const;  // a body with shape = mesh
  void chooseSupport(const std::vector<Vec<D>>& X, const std::vector<double>& V);
  void refuseOverlap(SectionReader& r, const std::vector<Vec<D>>& X, const std::vector<double>& V,
                     const std::string& what);
  void fillFreeFormBody();
  void checkIntegrationConstraint();
  const SurfacePatch<D>& namedSurface(SectionReader& r, const std::string& key = "surface");

  // [clamp.NAME], [prescribe.NAME] (ConditionSections.cpp).
  void addClamps();
  std::string readMotion(SectionReader& r, Prescription<D>& rule);
  static std::string motionText(const Prescription<D>& rule);
  void addNodalClamp(SectionReader& r, const std::string& name, std::set<std::string>& facesUsed);
  long ghostLayers(SectionReader& r);
  void addMirroredFileClamp(SectionReader& r, const std::string& name, const std::string& face);
  void readPrescriptions();

  // [gravity], [load.NAME], [initial.NAME] (LoadSections.cpp).
  void readLoads();
  void warnInteriorTraction(const Load<D>& load, const std::string& regionName);
  void readInitialConditions();

  // [output], [checkpoint], [guard], [probe.NAME] (OutputSections.cpp).
  void readOutput();
  void readCheckpoint();
  void readGuard();
  void readProbes();
  void resolveSurfaceProbe(Probe<D>& probe, const SurfacePatch<D>& surface);

  const Config& config_;
  SceneSetup<D> setup_;
  Eigen::AlignedBox<double, D> bodyBox_;
  std::size_t maxParticles_ = 0;
  double supportRatio_ = 2.0;
  bool particleFile_ = false;           // the body is read from a particle file
  bool integrationConstraint_ = false;  // [kernel] integration_constraint
  bool integrationLinear_ = false;      // ... = linear
  Index bodyCount_ = 0;
  std::map<std::array<long, D>, Index> latticeIndex_;  // lattice point -> body particle
  std::array<LatticeAxis, D> lattice_{};               // the bodies' lattice
  // A mesh body's physical groups of dimension d: their particles, for regions.
  std::map<std::string, std::vector<Index>> freeFormVolumes_;
  // Body particles a clamp holds (its face layer, or the layers its ghosts mirror): the clamp's
  // name and what it does, for the error when a [prescribe] region takes one of them too.
  std::map<Index, std::pair<std::string, std::string>> clampHeld_;
};

}  // namespace tlsph::scene_build
