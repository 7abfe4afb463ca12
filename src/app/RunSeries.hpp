// The CSV series of a run, one row each every [output] series_every_steps steps: energies.csv
// (the energy books, momentum), probes.csv (the [probe.NAME] values) and reactions.csv (the
// force each clamp and prescription exerts on the body).
#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "app/Checkpoint.hpp"
#include "app/Frames.hpp"
#include "explicit/Diagnostics.hpp"
#include "explicit/Solver.hpp"
#include "output/CsvSeries.hpp"
#include "scene/SceneSetup.hpp"

namespace tlsph {

template <int D>
std::vector<std::string> probeColumns(const SceneSetup<D>& setup) {
  std::vector<std::string> columns = {"time", "step"};
  const char* axes = "xyz";
  for (const auto& probe : setup.probes)
    for (const auto& q : probe.quantities) {
      if (q == "cauchy_stress") {
        for (const char* c : {"xx", "yy", "zz", "xy", "yz", "xz"})
          columns.push_back(probe.name + "_s" + c);
        continue;
      }
      for (int a = 0; a < D; ++a)
        columns.push_back(probe.name + "_" + (q == "displacement" ? "u" : "v") + axes[a]);
    }
  return columns;
}

// The Cauchy stress a surface probe recovers at its particle (method/SurfaceStress.hpp) at
// time t, from the particles' present displacements; `F` is the particle's own, the first guess.
template <int D>
Mat3 surfaceStressOf(const SceneSetup<D>& setup, const Probe<D>& probe, const Mat<D>& F, double t) {
  Vec<D> dead = Vec<D>::Zero();
  double following = 0.0;
  for (const auto& traction : probe.tractions) {
    dead += traction.ramp.factor(t) * traction.dead;
    following += traction.ramp.factor(t) * traction.followingPressure;
  }
  const Index i = probe.stencil->particle;
  const Mat<D> H =
      recoveredDisplacementGradient<D>(*probe.stencil, setup.scene.particles.displacement,
                                       setup.scene.materials[setup.scene.particles.material[i]],
                                       dead, following, F - Mat<D>::Identity());
  return cauchyStressOf(setup, Mat<D>(Mat<D>::Identity() + H), i);
}

template <int D>
std::vector<double> probeRow(const SceneSetup<D>& setup, const Solver<D>& solver) {
  const auto& p = setup.scene.particles;
  const auto& F = solver.forces().deformationGradient();
  const auto* quadrature = solver.forces().quadrature();
  std::vector<double> row = {solver.time(), double(solver.stepCount())};
  for (const auto& probe : setup.probes)
    for (const auto& q : probe.quantities) {
      if (q == "cauchy_stress") {
        // The weighted particle stresses (Shepard; the probe's weights), xx yy zz xy yz xz; a
        // surface probe's recovered from the surface and its traction.
        Mat3 s = Mat3::Zero();
        if (probe.stencil)
          s = surfaceStressOf(setup, probe, F[probe.particles[0]], solver.time());
        else
          for (std::size_t k = 0; k < probe.particles.size(); ++k)
            s +=
                probe.weights[k] * cauchyStressOf(setup, F[probe.particles[k]], probe.particles[k]);
        row.insert(row.end(), {s(0, 0), s(1, 1), s(2, 2), s(0, 1), s(1, 2), s(0, 2)});
        continue;
      }
      const bool displacement = q == "displacement";
      const auto& field = displacement ? p.displacement : p.velocity;
      const bool firstOrder = displacement && !probe.offsets.empty();
      Vec<D> value = Vec<D>::Zero();
      for (std::size_t k = 0; k < probe.particles.size(); ++k) {
        const Index j = probe.particles[k];
        Vec<D> u = field[j];
        if (firstOrder) u += (F[j] - Mat<D>::Identity()) * probe.offsets[k];  // u(X_J + d)
        // With [kernel] quadrature = taylor the fit's second derivatives are at hand: carry
        // u to second order, + 1/2 d . grad grad u_J d (the first-order carry reads a plate's
        // centre deflection 0.4 % high at 4 particles through, by 1/2 |w''| <d^2>).
        if (firstOrder && quadrature) {
          const auto G = TaylorQuadrature<D>::unpack(quadrature->secondGradients()[j]);
          for (int a = 0; a < D; ++a)
            u += 0.5 * probe.offsets[k][a] * (G[a] * probe.offsets[k]);
        }
        value += probe.weights[k] * u;
      }
      for (int a = 0; a < D; ++a)
        row.push_back(value[a]);
    }
  return row;
}

template <int D>
class RunSeries {
 public:
  // Nothing is written until flush(); `command` is recorded in each file's preamble.
  RunSeries(const SceneSetup<D>& setup, const std::string& command) : setup_(setup) {
    const OutputSettings& out = setup.output;
    const std::filesystem::path dir = out.directory;
    const std::vector<std::string> preamble = {
        "tlsph scene " + setup.name + " from " + setup.sourceFile, "command: " + command,
        "SI units: s, m, J, kg m/s"};
    std::vector<std::string> energyColumns = {
        "time",   "step",  "kinetic",  "strain",     "hourglass",  "external_work", "boundary_work",
        "damped", "total", "residual", "momentum_x", "momentum_y", "momentum_z"};
    if (out.hourglassContent) energyColumns.push_back("hourglass_content");
    energies_ = std::make_unique<CsvSeries>(dir / "energies.csv", energyColumns);
    energies_->setPreamble(preamble);
    if (!setup.probes.empty()) {
      probes_ = std::make_unique<CsvSeries>(dir / "probes.csv", probeColumns(setup));
      probes_->setPreamble(preamble);
    }
    const auto& rules = setup.scene.prescriptions;
    if (!rules.empty()) {
      std::vector<std::string> columns = {"time", "step"};
      for (const auto& rule : rules)
        for (int a = 0; a < D; ++a)
          columns.push_back(rule.name + "_" + "xyz"[a]);
      reactions_ = std::make_unique<CsvSeries>(dir / "reactions.csv", columns);
      reactions_->setPreamble(preamble);
    }
  }

  // A row of each series at the solver's present state (synchronised by the caller).
  // Distributed: a collective (the hourglass content sums over the ranks).
  void record(const Solver<D>& solver) {
    const auto& p = setup_.scene.particles;
    const EnergyBalance e = solver.energyBalance();
    Vec3 momentum = Vec3::Zero();
    momentum.head<D>() = linearMomentum(p);
    std::vector<double> row = {solver.time(),  double(solver.stepCount()),
                               e.kinetic,      e.strain,
                               e.hourglass,    e.externalWork,
                               e.boundaryWork, e.damped,
                               e.total(),      solver.residualRatio(),
                               momentum.x(),   momentum.y(),
                               momentum.z()};
    if (setup_.output.hourglassContent) {
      const auto& F = solver.forces().deformationGradient();
      std::vector<Mat<D>> H(F.begin(), F.end());
      for (auto& h : H)
        h -= Mat<D>::Identity();
      row.push_back(hourglassContent(solver.reference(), p.volume, p.displacement, H,
                                     solver.ownedParticles(), solver.communicator()));
    }
    energies_->append(row);
    if (probes_) probes_->append(probeRow(setup_, solver));
    if (reactions_) reactions_->append(reactionRow(solver));
  }

  void flush() {
    energies_->flush();
    if (probes_) probes_->flush();
    if (reactions_) reactions_->flush();
  }

  // Back to the rows a checkpoint counted (later ones, written before the stop, are dropped).
  void resume(const OutputProgress& o) {
    energies_->resume(o.energyRows);
    if (probes_) probes_->resume(o.probeRows);
    if (reactions_) reactions_->resume(o.reactionRows);
  }

  // The rows so far, for a checkpoint.
  void countRows(OutputProgress& o) const {
    o.energyRows = energies_->rowCount();
    o.probeRows = probes_ ? probes_->rowCount() : 0;
    o.reactionRows = reactions_ ? reactions_->rowCount() : 0;
  }

  // The files of the series this run writes (empty: not written).
  std::filesystem::path energiesFile() const { return energies_->path(); }
  std::filesystem::path probesFile() const { return probes_ ? probes_->path() : ""; }
  std::filesystem::path reactionsFile() const { return reactions_ ? reactions_->path() : ""; }

 private:
  std::vector<double> reactionRow(const Solver<D>& solver) const {
    std::vector<double> row = {solver.time(), double(solver.stepCount())};
    for (std::size_t r = 0; r < setup_.scene.prescriptions.size(); ++r) {
      const Vec<D> R = solver.reaction(r);
      row.insert(row.end(), R.data(), R.data() + D);
    }
    return row;
  }

  const SceneSetup<D>& setup_;
  std::unique_ptr<CsvSeries> energies_, probes_, reactions_;
};

}  // namespace tlsph
