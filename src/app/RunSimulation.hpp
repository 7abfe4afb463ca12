// The run loop of `tlsph run`: advance, check, write, report.
#pragma once

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <memory>
#include <optional>
#include <ostream>
#include <sstream>
#include <string>

#include "app/Frames.hpp"
#include "app/Guards.hpp"
#include "app/StopRequest.hpp"
#include "output/CsvSeries.hpp"
#include "output/VtuSeriesWriter.hpp"
#include "scene/SceneSetup.hpp"
#include "tlsph/Diagnostics.hpp"
#include "tlsph/Solver.hpp"

namespace tlsph {

struct RunOptions {
  bool progress = false;  // a live progress line (on a terminal only)
  std::string command;    // recorded in the CSV preamble, to reproduce the run
};

enum class RunOutcome { Finished, Converged, NotConverged, Unstable, Interrupted };

struct RunSummary {
  RunOutcome outcome = RunOutcome::Finished;
  long steps = 0;
  double time = 0.0;
  double timeStep = 0.0;
  StableStep stableStep;  // the wave-speed rule's step and what sets it
  double wallSeconds = 0.0;
  double residual = 0.0;
  EnergyBalance energy;
  std::filesystem::path pvd, energies, probes, reactions;
  // Final force each clamp and prescription exerts on the body (Solver::reaction), by name.
  std::vector<std::pair<std::string, Vec3>> finalReactions;
  std::string message;
  std::optional<Instability> instability;  // set when the outcome is Unstable
  std::optional<NewtonStatistics> newton;  // set for a Newton static run
};

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

template <int D>
std::vector<double> probeRow(const SceneSetup<D>& setup, const Solver<D>& solver) {
  const auto& p = setup.scene.particles;
  const auto& F = solver.forces().deformationGradient();
  std::vector<double> row = {solver.time(), double(solver.stepCount())};
  for (const auto& probe : setup.probes)
    for (const auto& q : probe.quantities) {
      if (q == "cauchy_stress") {
        // The weighted particle stresses (Shepard; the probe's weights), xx yy zz xy yz xz.
        Mat3 s = Mat3::Zero();
        for (std::size_t k = 0; k < probe.particles.size(); ++k)
          s += probe.weights[k] * cauchyStressOf(setup, F[probe.particles[k]], probe.particles[k]);
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
        value += probe.weights[k] * u;
      }
      for (int a = 0; a < D; ++a)
        row.push_back(value[a]);
    }
  return row;
}

// onStart sees the solver once it is set up (neighbours, dt), before the first step.
template <int D, class OnStart>
RunSummary runSimulation(SceneSetup<D>& setup, const RunOptions& options, OnStart&& onStart) {
  namespace fs = std::filesystem;
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  Solver<D> solver(setup.scene, setup.solver);
  onStart(solver);
  const auto& p = setup.scene.particles;
  const RunSettings& run = setup.run;
  const OutputSettings& out = setup.output;
  const fs::path dir = out.directory;

  std::unique_ptr<VtuSeriesWriter> vtu;
  if (!out.fields.empty()) vtu = std::make_unique<VtuSeriesWriter>(dir, setup.name);
  const std::vector<std::string> preamble = {
      "tlsph scene " + setup.name + " from " + setup.sourceFile, "command: " + options.command,
      "SI units: s, m, J, kg m/s"};
  std::vector<std::string> energyColumns = {
      "time",   "step",  "kinetic",  "strain",     "hourglass",  "external_work", "boundary_work",
      "damped", "total", "residual", "momentum_x", "momentum_y", "momentum_z"};
  if (out.hourglassContent) energyColumns.push_back("hourglass_content");
  CsvSeries energies(dir / "energies.csv", energyColumns);
  energies.setPreamble(preamble);
  std::unique_ptr<CsvSeries> probes;
  if (!setup.probes.empty()) {
    probes = std::make_unique<CsvSeries>(dir / "probes.csv", probeColumns(setup));
    probes->setPreamble(preamble);
  }

  // reactions.csv: the force each clamp and prescription exerts on the body.
  std::unique_ptr<CsvSeries> reactions;
  const auto& rules = setup.scene.prescriptions;
  if (!rules.empty()) {
    std::vector<std::string> columns = {"time", "step"};
    for (const auto& rule : rules)
      for (int a = 0; a < D; ++a)
        columns.push_back(rule.name + "_" + "xyz"[a]);
    reactions = std::make_unique<CsvSeries>(dir / "reactions.csv", columns);
    reactions->setPreamble(preamble);
  }
  auto reactionRow = [&] {
    std::vector<double> row = {solver.time(), double(solver.stepCount())};
    for (std::size_t r = 0; r < rules.size(); ++r) {
      const Vec<D> R = solver.reaction(r);
      row.insert(row.end(), R.data(), R.data() + D);
    }
    return row;
  };

  auto recordSeries = [&] {
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
    if (out.hourglassContent) {
      std::vector<Mat<D>> H = solver.forces().deformationGradient();
      for (auto& h : H)
        h -= Mat<D>::Identity();
      row.push_back(hourglassContent(solver.reference(), p.volume, p.displacement, H));
    }
    energies.append(row);
    if (probes) probes->append(probeRow(setup, solver));
    if (reactions) reactions->append(reactionRow());
  };
  long lastFrameStep = -1;
  auto writeFrame = [&] {
    if (vtu && lastFrameStep != solver.stepCount()) vtu->write(makeFrame(setup, solver));
    lastFrameStep = solver.stepCount();
    energies.flush();
    if (probes) probes->flush();
    if (reactions) reactions->flush();
  };

  RunSummary summary;
  summary.timeStep = solver.timeStep();
  summary.stableStep = solver.stableStepRule();
  recordSeries();
  writeFrame();
  RunGuard<D> guard(setup, solver);  // the stability guards (Guards.hpp)
  // What every run reports at its end (steps, residual and energy books: the caller).
  auto finish = [&] {
    summary.wallSeconds = std::chrono::duration<double>(Clock::now() - start).count();
    if (vtu) summary.pvd = vtu->pvdPath();
    summary.energies = dir / "energies.csv";
    if (probes) summary.probes = dir / "probes.csv";
    if (reactions) summary.reactions = dir / "reactions.csv";
    for (std::size_t r = 0; r < rules.size(); ++r) {
      Vec3 R = Vec3::Zero();
      R.head<D>() = solver.reaction(r);
      summary.finalReactions.emplace_back(rules[r].name, R);
    }
    return summary;
  };
  auto interruptedMessage = [&] {
    std::ostringstream m;
    m << "stopped by signal " << int(stopSignal()) << " at step " << solver.stepCount()
      << ", t = " << solver.time() << " s: the output holds the state at that step";
    return m.str();
  };
  if (run.newtonStatic()) {
    // Load steps to equilibrium: one series row and one frame per converged step.
    NewtonSolver<D> newton(setup.scene, solver, run.newton);
    try {
      newton.run([&] {
        recordSeries();
        writeFrame();
        if (stopRequested()) return false;
        if (options.progress) {
          const auto& st = newton.statistics();
          std::fprintf(stderr,
                       "\r\033[Kload step %d  t = %.4g s of %.4g  Newton iterations %d  "
                       "residual %.3g (target %.3g)",
                       st.loadSteps, solver.time(), solver.rampEnd(), st.iterations,
                       solver.residualRatio(), run.tolerance);
          std::fflush(stderr);
        }
        return true;
      });
      summary.outcome = stopRequested() ? RunOutcome::Interrupted : RunOutcome::Converged;
      if (stopRequested()) summary.message = interruptedMessage();
    } catch (const NewtonFailure& failure) {
      summary.outcome = RunOutcome::NotConverged;
      summary.message = failure.what();
      recordSeries();
      writeFrame();
    }
    if (options.progress) std::fprintf(stderr, "\r\033[K");
    summary.newton = newton.statistics();
    summary.steps = solver.stepCount();
    summary.time = solver.time();
    summary.residual = solver.residualRatio();
    summary.energy = solver.energyBalance();
    return finish();
  }
  double nextFrameTime = out.everyTime;
  auto lastProgress = Clock::now();
  // The CSV series reach the disk at least every flushSeconds of wall time, so a run that is
  // killed leaves its series up to then (frames flush them too).
  auto lastFlush = Clock::now();
  const auto flushInterval = std::chrono::duration<double>(out.flushSeconds);
  const double endTime = run.endTime * (1.0 - 1e-12);
  while (true) {
    if (solver.time() >= endTime) {
      summary.outcome = run.quasiStatic ? RunOutcome::NotConverged : RunOutcome::Finished;
      break;
    }
    if (run.maxSteps > 0 && solver.stepCount() >= run.maxSteps) {
      summary.outcome = run.quasiStatic ? RunOutcome::NotConverged : RunOutcome::Finished;
      summary.message =
          "stopped at the step limit [time] max_steps = " + std::to_string(run.maxSteps);
      break;
    }
    if (stopRequested()) {
      summary.outcome = RunOutcome::Interrupted;
      summary.message = interruptedMessage();
      break;
    }
    solver.step();
    const long step = solver.stepCount();
    if (step % run.checkEvery == 0) {
      summary.instability = guard.check();
      if (summary.instability) {
        summary.outcome = RunOutcome::Unstable;
        break;
      }
      if (run.quasiStatic && solver.time() >= solver.rampEnd() &&
          solver.residualRatio() < run.tolerance) {
        summary.outcome = RunOutcome::Converged;
        break;
      }
    }
    if (step % out.seriesEverySteps == 0) {
      recordSeries();
      if (Clock::now() - lastFlush > flushInterval) {
        energies.flush();
        if (probes) probes->flush();
        if (reactions) reactions->flush();
        lastFlush = Clock::now();
      }
    }
    const bool frameDue = out.everySteps > 0 ? step % out.everySteps == 0
                                             : solver.time() >= nextFrameTime * (1.0 - 1e-12);
    if (frameDue) {
      writeFrame();
      while (out.everyTime > 0 && nextFrameTime <= solver.time() * (1.0 + 1e-12))
        nextFrameTime += out.everyTime;
    }
    if (options.progress && Clock::now() - lastProgress > std::chrono::milliseconds(500)) {
      lastProgress = Clock::now();
      const double wall = std::chrono::duration<double>(lastProgress - start).count();
      const EnergyBalance e = solver.energyBalance();
      std::fprintf(stderr, "\r\033[Kstep %ld  t = %.4g s of %.4g  dt = %.3g  ", step, solver.time(),
                   run.endTime, solver.timeStep());
      if (run.quasiStatic)
        std::fprintf(stderr, "residual %.3g (target %.3g)  ", solver.residualRatio(),
                     run.tolerance);
      const double eta = wall * (run.endTime - solver.time()) / std::max(solver.time(), 1e-300);
      std::fprintf(stderr, "ETA %s%.0f s  E_kin %.3g  E_strain %.3g", run.quasiStatic ? "<= " : "",
                   eta, e.kinetic, e.strain);
      std::fflush(stderr);
    }
  }
  if (options.progress) std::fprintf(stderr, "\r\033[K");

  summary.steps = solver.stepCount();
  summary.time = solver.time();
  summary.residual = solver.residualRatio();
  if (summary.outcome != RunOutcome::Unstable) {
    recordSeries();
    writeFrame();
    summary.energy = solver.energyBalance();
  } else {
    energies.flush();
    if (probes) probes->flush();
    if (reactions) reactions->flush();
    summary.energy = solver.energyBalance();  // the failing state's books
    guard.writeFrames(*summary.instability);  // leaves the solver in the last good state
  }
  return finish();
}

}  // namespace tlsph
