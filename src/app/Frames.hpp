// What the writers observe: per-particle output fields assembled from the solver's state,
// only those the scene asked for.
#pragma once

#include <algorithm>

#include <cmath>
#include <span>
#include <string>
#include <vector>

#include "explicit/Solver.hpp"
#include "output/Frame.hpp"
#include "scene/SceneSetup.hpp"

namespace tlsph {

// Weighted RMS over the neighbours of eps_IJ / |X_IJ| (6.81): the relative mismatch between
// the pair's current separation and the one F predicts; large where hourglass modes grow.
template <int D>
std::vector<double> hourglassError(const ReferenceConfiguration<D>& ref,
                                   const std::vector<Vec<D>>& u, std::span<const Mat<D>> F,
                                   const std::vector<Index>* particles = nullptr) {
  const auto& nb = ref.neighbours;
  std::vector<double> out(ref.particleCount(), 0.0);
  const Index count = particles ? static_cast<Index>(particles->size()) : ref.particleCount();
  for (Index p = 0; p < count; ++p) {
    const Index i = particles ? (*particles)[p] : p;
    double sum = 0.0, weight = 0.0;
    for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k) {
      const Index j = nb.neighbour[k];
      const Vec<D>& Xij = ref.separation[k];
      const Vec<D> xij = Xij + (u[i] - u[j]);
      const double eps = (xij - 0.5 * ((F[i] + F[j]) * Xij)).dot(xij) / xij.norm();
      sum += ref.kernelValue[k] * std::pow(eps / Xij.norm(), 2);
      weight += ref.kernelValue[k];
    }
    out[i] = weight > 0.0 ? std::sqrt(sum / weight) : 0.0;
  }
  return out;
}

// The full 3D first Piola-Kirchhoff stress of particle i for its F (in plane strain F_33 = 1,
// so P_33 and sigma_33 are not zero), and the Cauchy stress sigma = P F^T / J.
template <int D>
Mat3 firstPiolaOf(const SceneSetup<D>& setup, const Mat<D>& F, Index i) {
  const Mat3 F3 = embedDeformationGradient<D>(F);
  return std::visit([&](const auto& model) { return model.firstPiolaKirchhoff(F3); },
                    setup.scene.materials[setup.scene.particles.material[i]]);
}

template <int D>
Mat3 cauchyStressOf(const SceneSetup<D>& setup, const Mat<D>& F, Index i) {
  const Mat3 F3 = embedDeformationGradient<D>(F);
  return firstPiolaOf(setup, F, i) * F3.transpose() / F3.determinant();
}

// Every field name makeFrame knows, in the order of docs/scene-format.md ([output] fields).
inline const std::vector<std::string>& allFrameFields() {
  static const std::vector<std::string> names = {"displacement",    "velocity",      "J",
                                                 "von_mises",       "cauchy_stress", "first_piola",
                                                 "hourglass_error", "flags"};
  return names;
}

// The hourglass_error field when `fields` asks for it (else empty), one value per particle.
// A distributed rank keeps pair data for its own particles only: each computes theirs, and
// with `whole` the field is gathered, so every rank calls this (after Solver::synchronize());
// without, only the rank's own values are set (for its piece of a frame).
template <int D>
std::vector<double> hourglassErrorField(const SceneSetup<D>& setup, const Solver<D>& solver,
                                        const std::vector<std::string>& fields, bool whole = true) {
  if (std::find(fields.begin(), fields.end(), "hourglass_error") == fields.end()) return {};
  std::vector<double> out =
      hourglassError<D>(solver.reference(), setup.scene.particles.displacement,
                        solver.forces().deformationGradient(), solver.ownedParticles());
  if (Communicator* comm = solver.communicator(); comm && whole) comm->gatherAll(out);
  return out;
}

// The frame of every particle, or with `piece` of those particles only (ascending), each point
// carrying its particle number (Frame::ids): a distributed rank's piece. hourglassError: the
// field from hourglassErrorField (computed here when null).
template <int D>
Frame makeFrame(const SceneSetup<D>& setup, const Solver<D>& solver,
                const std::vector<std::string>& fields,
                const std::vector<double>* hourglassErrorValues = nullptr,
                const std::vector<Index>* piece = nullptr) {
  const auto& p = setup.scene.particles;
  const Index n = piece ? static_cast<Index>(piece->size()) : p.size();
  auto particle = [&](Index k) { return piece ? (*piece)[k] : k; };
  Frame frame;
  frame.time = solver.time();
  frame.step = solver.stepCount();
  frame.points.resize(n);
  for (Index k = 0; k < n; ++k) {
    frame.points[k] = {0.0, 0.0, 0.0};
    const Vec<D> x = p.currentPosition(particle(k));
    for (int a = 0; a < D; ++a)
      frame.points[k][a] = x[a];
  }
  if (piece) frame.ids.emplace(piece->begin(), piece->end());
  auto scalarField = [&](const std::string& name, auto&& value) {
    PointField f{name, 1, std::vector<double>(n)};
    for (Index k = 0; k < n; ++k)
      f.values[k] = value(particle(k));
    frame.fields.push_back(std::move(f));
  };
  auto vectorField = [&](const std::string& name, const std::vector<Vec<D>>& v) {
    PointField f{name, 3, std::vector<double>(3 * n, 0.0)};
    for (Index k = 0; k < n; ++k)
      for (int a = 0; a < D; ++a)
        f.values[3 * k + a] = v[particle(k)][a];
    frame.fields.push_back(std::move(f));
  };
  auto flagField = [&](const std::string& name, auto&& value) {
    PointFlags f{name, std::vector<std::uint8_t>(n)};
    for (Index k = 0; k < n; ++k)
      f.values[k] = value(particle(k));
    frame.flags.push_back(std::move(f));
  };
  const auto& F = solver.forces().deformationGradient();
  for (const auto& name : fields) {
    if (name == "displacement") {
      vectorField(name, p.displacement);
    } else if (name == "velocity") {
      vectorField(name, p.velocity);
    } else if (name == "J") {
      scalarField(name, [&](Index i) { return F[i].determinant(); });
    } else if (name == "von_mises") {
      scalarField(name, [&](Index i) {
        const Mat3 sigma = cauchyStressOf(setup, F[i], i);
        const Mat3 dev = sigma - sigma.trace() / 3.0 * Mat3::Identity();
        return std::sqrt(1.5 * dev.squaredNorm());
      });
    } else if (name == "first_piola" || name == "cauchy_stress") {
      PointField f{name, 9, std::vector<double>(9 * n)};
      for (Index k = 0; k < n; ++k) {
        const Index i = particle(k);
        const Mat3 out =
            name == "first_piola" ? firstPiolaOf(setup, F[i], i) : cauchyStressOf(setup, F[i], i);
        for (int r = 0; r < 3; ++r)
          for (int c = 0; c < 3; ++c)
            f.values[9 * k + 3 * r + c] = out(r, c);
      }
      frame.fields.push_back(std::move(f));
    } else if (name == "hourglass_error") {
      const bool given = hourglassErrorValues && !hourglassErrorValues->empty();
      const std::vector<double> computed =
          given ? std::vector<double>() : hourglassError<D>(solver.reference(), p.displacement, F);
      const std::vector<double>& values = given ? *hourglassErrorValues : computed;
      scalarField(name, [&](Index i) { return values[i]; });
    } else if (name == "flags") {
      flagField("ghost", [&](Index i) { return setup.ghost[i]; });
      flagField("prescribed", [&](Index i) { return p.motion[i] == Motion::Prescribed; });
      flagField("body", [&](Index i) { return setup.body[i]; });
    }
  }
  return frame;
}

}  // namespace tlsph
