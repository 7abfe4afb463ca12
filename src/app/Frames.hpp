// What the writers observe: per-particle output fields assembled from the solver's state,
// only those the scene asked for.
#pragma once

#include <algorithm>

#include <cmath>
#include <string>
#include <vector>

#include "output/Frame.hpp"
#include "scene/SceneSetup.hpp"
#include "tlsph/Solver.hpp"

namespace tlsph {

// Weighted RMS over the neighbours of eps_IJ / |X_IJ| (6.81): the relative mismatch between
// the pair's current separation and the one F predicts; large where hourglass modes grow.
template <int D>
std::vector<double> hourglassError(const ReferenceConfiguration<D>& ref,
                                   const std::vector<Vec<D>>& u, const std::vector<Mat<D>>& F,
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

// The hourglass_error field of every particle when `fields` asks for it (else empty). A
// distributed rank keeps pair data for its own particles only: each computes theirs and the
// field is gathered, so every rank calls this (after Solver::synchronize()).
template <int D>
std::vector<double> hourglassErrorField(const SceneSetup<D>& setup, const Solver<D>& solver,
                                        const std::vector<std::string>& fields) {
  if (std::find(fields.begin(), fields.end(), "hourglass_error") == fields.end()) return {};
  std::vector<double> out =
      hourglassError<D>(solver.reference(), setup.scene.particles.displacement,
                        solver.forces().deformationGradient(), solver.ownedParticles());
  if (Communicator* comm = solver.communicator()) comm->gatherAll(out);
  return out;
}

// hourglassError: the field from hourglassErrorField (computed here when null).
template <int D>
Frame makeFrame(const SceneSetup<D>& setup, const Solver<D>& solver,
                const std::vector<std::string>& fields,
                const std::vector<double>* hourglassErrorValues = nullptr) {
  const auto& p = setup.scene.particles;
  const Index n = p.size();
  Frame frame;
  frame.time = solver.time();
  frame.step = solver.stepCount();
  frame.points.resize(n);
  for (Index i = 0; i < n; ++i) {
    frame.points[i] = {0.0, 0.0, 0.0};
    const Vec<D> x = p.currentPosition(i);
    for (int a = 0; a < D; ++a)
      frame.points[i][a] = x[a];
  }
  auto vectorField = [&](const std::string& name, const std::vector<Vec<D>>& v) {
    PointField f{name, 3, std::vector<double>(3 * n, 0.0)};
    for (Index i = 0; i < n; ++i)
      for (int a = 0; a < D; ++a)
        f.values[3 * i + a] = v[i][a];
    frame.fields.push_back(std::move(f));
  };
  const auto& F = solver.forces().deformationGradient();
  for (const auto& name : fields) {
    if (name == "displacement") {
      vectorField(name, p.displacement);
    } else if (name == "velocity") {
      vectorField(name, p.velocity);
    } else if (name == "J") {
      PointField f{name, 1, std::vector<double>(n)};
      for (Index i = 0; i < n; ++i)
        f.values[i] = F[i].determinant();
      frame.fields.push_back(std::move(f));
    } else if (name == "first_piola" || name == "cauchy_stress" || name == "von_mises") {
      PointField f{name, name == "von_mises" ? 1 : 9, {}};
      f.values.resize(f.components * n);
      for (Index i = 0; i < n; ++i) {
        const Mat3 out =
            name == "first_piola" ? firstPiolaOf(setup, F[i], i) : cauchyStressOf(setup, F[i], i);
        if (name == "von_mises") {
          const Mat3 dev = out - out.trace() / 3.0 * Mat3::Identity();
          f.values[i] = std::sqrt(1.5 * dev.squaredNorm());
        } else {
          for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c)
              f.values[9 * i + 3 * r + c] = out(r, c);
        }
      }
      frame.fields.push_back(std::move(f));
    } else if (name == "hourglass_error") {
      frame.fields.push_back(
          PointField{name, 1,
                     hourglassErrorValues && !hourglassErrorValues->empty()
                         ? *hourglassErrorValues
                         : hourglassError<D>(solver.reference(), p.displacement, F)});
    } else if (name == "flags") {
      frame.flags.push_back(PointFlags{"ghost", setup.ghost});
      std::vector<std::uint8_t> prescribed(n);
      for (Index i = 0; i < n; ++i)
        prescribed[i] = p.motion[i] == Motion::Prescribed;
      frame.flags.push_back(PointFlags{"prescribed", prescribed});
      frame.flags.push_back(PointFlags{"body", setup.body});
    }
  }
  return frame;
}

}  // namespace tlsph
