// [clamp.NAME] and [prescribe.NAME]: the particles whose motion is given, and the clamps'
// ghost layers.
#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <string>
#include <vector>

#include "scene/Builder.hpp"

namespace tlsph::scene_build {

// A mirrored clamp's `layers`: at least ceil(H/dx), so that the kernel support is full.
template <int D>
long Builder<D>::ghostLayers(SectionReader& r) {
  const int needed = static_cast<int>(std::ceil(supportRatio_ - 1e-9));
  const long layers = r.integer("layers", needed);
  if (layers < needed)
    throw r.error("layers", std::to_string(layers) +
                                " ghost layers do not fill the kernel support (H/dx = " +
                                fmt(supportRatio_) + " needs " + std::to_string(needed) + ")");
  return layers;
}

template <int D>
void Builder<D>::addClamps() {
  auto& p = setup_.scene.particles;
  const auto& X = p.referencePosition;
  std::set<std::string> facesUsed;
  for (const auto& name : config_.namesOf("clamp")) {
    SectionReader r(config_, "clamp." + name);
    if (setup_.freeForm) {
      addNodalClamp(r, name, facesUsed);
      continue;
    }
    if (r.has("surface"))
      throw r.error("surface",
                    "named surfaces belong to a body meshed from a CAD or mesh file (shape = "
                    "mesh); a lattice body is clamped on a face of its bounding box (face = x-, "
                    "...)");
    const std::string face = r.word("face", std::nullopt, faceNames());
    if (!facesUsed.insert(face).second) throw r.error("face", "face " + face + " is clamped twice");
    const std::string method = r.word("method", "mirror", {"mirror", "mirror-quadratic", "fixed"});
    const long layers = ghostLayers(r);
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
      throw r.error("layers", std::to_string(layers) + " ghost layers of the " +
                                  std::to_string(onFace) + " particles on face " + face + " make " +
                                  fmt(total) + " particles, more than [scene] max_particles = " +
                                  std::to_string(maxParticles_));
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
          throw r.error("layers",
                        std::to_string(layers) + " ghost layers reach beyond the lattice's range");
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
    setup_.conditions.push_back("clamp." + name + ": face " + face + ", " + method + ", " +
                                (motion == "fixed" ? "" : motion + " " + motionText(clamp) + ", ") +
                                std::to_string(layers) + " ghost layers, " +
                                std::to_string(ghosts) + " ghost particles");
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

// A clamp on a body read from a file: its particles on the named surface (or on a face of the
// bounding box) are held, following the clamp's motion. A mesh body's surface particles lie on
// the surface, so u = u_p holds on the surface itself; there are no ghosts (mirroring needs the
// lattice's layers).
template <int D>
void Builder<D>::addNodalClamp(SectionReader& r, const std::string& name,
                               std::set<std::string>& facesUsed) {
  auto& p = setup_.scene.particles;
  // A particle file's face is mirrored by default, as a lattice body's; a mesh's particles lie
  // on its surface, which is where a nodal clamp holds them.
  const bool mirrorable = particleFile_ && !r.has("surface");
  const std::string method = r.word("method", mirrorable ? "mirror" : "nodal",
                                    {"nodal", "mirror", "mirror-quadratic", "fixed"});
  if (method == "mirror" && mirrorable) {
    const std::string face = r.word("face", std::nullopt, faceNames());
    if (!facesUsed.insert(face).second) throw r.error("face", "face " + face + " is clamped twice");
    addMirroredFileClamp(r, name, face);
    return;
  }
  if (method != "nodal")
    throw r.error("method",
                  mirrorable
                      ? "a face of a particle file is clamped by mirroring (method = mirror, "
                        "the default) or by holding its particles (nodal); '" +
                            method + "' needs the lattice's layers behind a face"
                      : "a body meshed from a file is clamped at its particles on the surface "
                        "(method = nodal): '" +
                            method + "' needs particles behind a plane face to mirror");
  if (r.has("at")) throw r.error("at", "applies only with method = mirror on a particle file");
  std::vector<Index> held;
  std::string where;
  if (r.has("surface")) {
    if (r.has("face")) throw r.error("face", "give either face or surface, not both");
    const std::string surface = config_.get("clamp." + name, "surface");
    held = namedSurface(r).particles;
    if (!facesUsed.insert("surface " + surface).second)
      throw r.error("surface", "surface " + surface + " is clamped twice");
    where = "surface " + surface;
  } else {
    const std::string face = r.word("face", std::nullopt, faceNames());
    if (!facesUsed.insert(face).second) throw r.error("face", "face " + face + " is clamped twice");
    for (Index i = 0; i < bodyCount_; ++i)
      if (onBoundingFace(i, face)) held.push_back(i);
    where = "face " + face;
  }
  Prescription<D> clamp;
  clamp.name = "clamp." + name;
  const std::string motion = readMotion(r, clamp);
  r.finish();
  for (Index i : held) {
    if (const auto c = clampHeld_.find(i); c != clampHeld_.end())
      throw r.error(r.has("surface") ? "surface" : "face",
                    "particle " + std::to_string(i) + " at " + fmt<D>(p.referencePosition[i]) +
                        " is held by [clamp." + c->second.first +
                        "] too: clamps that share particles (surfaces meeting at an edge) would "
                        "hold them twice; clamp the union as one surface in the CAD model");
    clampHeld_.emplace(i, std::pair{name, "holds " + where});
    p.motion[i] = Motion::Prescribed;
  }
  clamp.particles = held;
  setup_.conditions.push_back("clamp." + name + ": " + where + ", nodal, " +
                              (motion == "fixed" ? "" : motion + " " + motionText(clamp) + ", ") +
                              std::to_string(held.size()) + " particles held");
  setup_.scene.prescriptions.push_back(std::move(clamp));
}

// A clamp at a face of a body read from a particle file, mirrored as a lattice body's is: the
// face is a plane (given, or where the particles' cells end), and every particle within the
// ghost layers' depth of it gets a ghost at its reflection that takes the odd reflection of its
// displacement (MirrorGhost), so u = 0 sits on the plane, not half a spacing inside the body.
template <int D>
void Builder<D>::addMirroredFileClamp(SectionReader& r, const std::string& name,
                                      const std::string& face) {
  auto& p = setup_.scene.particles;
  const auto& X = p.referencePosition;
  const int axis = face[0] - 'x';
  const double sign = face[1] == '-' ? -1.0 : 1.0;  // the outward normal along the axis
  auto spacing = [&](Index i) { return std::pow(p.volume[i], 1.0 / D); };
  // Where the particles' cells end: the plane a lattice body's face would be.
  double cellEdge = -sign * std::numeric_limits<double>::infinity();
  for (Index i = 0; i < bodyCount_; ++i) {
    const double edge = X[i][axis] + sign * 0.5 * spacing(i);
    cellEdge = sign > 0 ? std::max(cellEdge, edge) : std::min(cellEdge, edge);
  }
  const double plane = r.has("at") ? r.number("at") : cellEdge;
  const long layers = ghostLayers(r);
  Prescription<D> clamp;
  clamp.name = "clamp." + name;
  const std::string motion = readMotion(r, clamp);
  // Every particle must lie on the body's side of the plane.
  for (Index i = 0; i < bodyCount_; ++i)
    if (sign * (X[i][axis] - plane) >= 0.0)
      throw r.error("at", "particle " + std::to_string(i) + " at " + fmt<D>(X[i]) +
                              " lies on or beyond the clamp's plane " + face.substr(0, 1) + " = " +
                              fmt(plane) + " (face " + face + ")");
  r.finish();
  const std::string holds = "mirrors the particles within " + std::to_string(layers) +
                            " spacings of the plane " + face.substr(0, 1) + " = " + fmt(plane);
  const int rule = static_cast<int>(setup_.scene.prescriptions.size());
  Index ghosts = 0;
  for (Index i = 0; i < bodyCount_; ++i) {
    const double depth = sign * (plane - X[i][axis]);
    if (depth >= double(layers) * spacing(i)) continue;
    if (const auto c = clampHeld_.find(i); c != clampHeld_.end())
      throw r.error("face", "particle " + std::to_string(i) + " at " + fmt<D>(X[i]) +
                                " is mirrored by [clamp." + c->second.first +
                                "] too: two clamped faces closer than the ghost layers' depth");
    clampHeld_.emplace(i, std::pair{name, holds});
    Vec<D> G = X[i];
    G[axis] = 2.0 * plane - X[i][axis];
    MirrorGhost m;
    m.mirror = i;
    m.motion = rule;
    const std::uint16_t mat = p.material[i];
    m.ghost = p.add(G, p.volume[i], p.mass[i], mat, Motion::Mirrored);
    setup_.scene.mirrorGhosts.push_back(m);
    setup_.body.push_back(setup_.body[i]);
    setup_.ghost.push_back(1);
    ++ghosts;
  }
  if (static_cast<double>(p.size()) > double(maxParticles_))
    throw r.error("layers", "the ghosts make " + std::to_string(p.size()) +
                                " particles, more than [scene] max_particles = " +
                                std::to_string(maxParticles_));
  setup_.conditions.push_back(
      "clamp." + name + ": face " + face + " at " + face.substr(0, 1) + " = " + fmt(plane) +
      ", mirror, " + (motion == "fixed" ? "" : motion + " " + motionText(clamp) + ", ") +
      std::to_string(layers) + " ghost layers, " + std::to_string(ghosts) + " ghost particles");
  setup_.scene.prescriptions.push_back(std::move(clamp));
}

// The `motion` of a prescription or a clamp and its keys; returns the motion's name.
template <int D>
std::string Builder<D>::readMotion(SectionReader& r, Prescription<D>& rule) {
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

template <int D>
std::string Builder<D>::motionText(const Prescription<D>& rule) {
  return rule.motion == PrescribedMotion::Fixed ? ""
         : rule.motion == PrescribedMotion::Rotation
             ? rotationText<D>(rule.axis, rule.point, rule.rate)
             : fmt<D>(rule.value);
}

template <int D>
void Builder<D>::readPrescriptions() {
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

template void Builder<2>::addClamps();
template void Builder<2>::addNodalClamp(SectionReader&, const std::string&, std::set<std::string>&);
template void Builder<3>::addNodalClamp(SectionReader&, const std::string&, std::set<std::string>&);
template std::string Builder<2>::readMotion(SectionReader&, Prescription<2>&);
template std::string Builder<2>::motionText(const Prescription<2>&);
template void Builder<2>::readPrescriptions();
template void Builder<3>::addClamps();
template std::string Builder<3>::readMotion(SectionReader&, Prescription<3>&);
template std::string Builder<3>::motionText(const Prescription<3>&);
template void Builder<3>::readPrescriptions();

template long Builder<2>::ghostLayers(SectionReader&);
template long Builder<3>::ghostLayers(SectionReader&);
template void Builder<2>::addMirroredFileClamp(SectionReader&, const std::string&,
                                               const std::string&);
template void Builder<3>::addMirroredFileClamp(SectionReader&, const std::string&,
                                               const std::string&);

}  // namespace tlsph::scene_build
