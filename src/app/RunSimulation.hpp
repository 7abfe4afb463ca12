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
#include <stdexcept>
#include <string>

#include "app/Checkpoint.hpp"
#include "app/CheckpointSchedule.hpp"
#include "app/Frames.hpp"
#include "app/Guards.hpp"
#include "app/RunSeries.hpp"
#include "app/SpectralLimit.hpp"
#include "app/StopRequest.hpp"
#include "explicit/Diagnostics.hpp"
#include "explicit/Solver.hpp"
#include "output/VtuSeriesWriter.hpp"
#include "scene/InputError.hpp"
#include "scene/SceneSetup.hpp"

namespace tlsph {

struct RunOptions {
  bool progress = false;    // a live progress line (on a terminal only)
  std::string command;      // recorded in the CSV preamble, to reproduce the run
  CheckpointOrigin origin;  // recorded in each checkpoint: the scene and the program
  // A distributed run (null: serial). Every rank runs the loop below on the same gathered
  // state and takes the same decisions; rank 0 alone writes files.
  Communicator* comm = nullptr;
};

// OutputFailed: a file could not be written (disk full, no permission): the run stops.
enum class RunOutcome { Finished, Converged, NotConverged, Unstable, Interrupted, OutputFailed };

struct RunSummary {
  RunOutcome outcome = RunOutcome::Finished;
  long steps = 0;
  double time = 0.0;
  double timeStep = 0.0;
  StableStep stableStep;      // the wave-speed rule's step and what sets it
  SpectralStep spectralStep;  // the operator's cap on it
  double wallSeconds = 0.0;
  double residual = 0.0;
  EnergyBalance energy;
  std::filesystem::path pvd, energies, probes, reactions;
  // Final force each clamp and prescription exerts on the body (Solver::reaction), by name.
  std::vector<std::pair<std::string, Vec3>> finalReactions;
  std::string message;
  std::optional<Instability> instability;  // set when the outcome is Unstable
  std::optional<NewtonStatistics> newton;  // set for a Newton static run
  std::filesystem::path checkpoint;        // the last checkpoint this run wrote
  long checkpointsWritten = 0;
  long restartedAtStep = -1;   // the checkpoint's step when the run was restarted
  PartitionSummary partition;  // ranks, and how the particles were split among them
};

// A file of the run's output could not be written; the run stops (RunOutcome::OutputFailed).
class OutputWriteFailure : public std::runtime_error {
  using std::runtime_error::runtime_error;
};

// onStart sees the solver once it is set up (neighbours, dt), before the first step. With
// `resume`, the run continues from that checkpoint (its output directory holds the run's output
// up to there) and ends bit for bit where the uninterrupted run would have.
template <int D, class OnStart>
RunSummary runSimulation(SceneSetup<D>& setup, const RunOptions& options, OnStart&& onStart,
                         const Checkpoint<D>* resume = nullptr) {
  namespace fs = std::filesystem;
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  Communicator* comm = options.comm;
  const bool root = !comm || comm->rank() == 0;
  if (comm && setup.run.newtonStatic())
    throw SetupError(
        "the Newton solver ([static] solver = newton) runs on one rank only: start "
        "it without mpirun (or with -np 1), or use solver = damped");
  // A rank holds the displacements of its particles and their halo only, not necessarily of
  // every corner of the facets its particles share.
  if (comm && comm->size() > 1 && !setup.followingLoad.empty())
    throw InputError(setup.followingWhere, setup.followingLoad, "follow",
                     "a following pressure runs on one rank only: start it without mpirun (or "
                     "with -np 1), or make the pressure dead (follow = false)");
  Solver<D> solver(setup.scene, setup.solver, comm);
  applySpectralStep(setup, solver);
  onStart(solver);
  if (resume) solver.restore(resume->solver);
  const RunSettings& run = setup.run;
  const OutputSettings& out = setup.output;
  const fs::path dir = out.directory;

  // Serially one .vtu per frame; distributed, each rank writes its piece and rank 0 the index.
  std::unique_ptr<VtuSeriesWriter> vtu;
  if (!out.fields.empty()) vtu = std::make_unique<VtuSeriesWriter>(dir, setup.name);
  RunSeries<D> series(setup, options.command);
  auto recordSeries = [&] {
    solver.synchronize();
    series.record(solver);
  };
  // Every write goes through here: a failure stops the run as OutputFailed. Rank 0 writes and
  // tells the others how it went.
  auto writing = [&](auto&& write) {
    std::string failure;
    if (root) {
      try {
        write();
      } catch (const std::exception& e) {
        failure = e.what();
        if (failure.empty()) failure = "unknown error";
      }
    }
    if (comm) comm->broadcast(failure);
    if (!failure.empty()) throw OutputWriteFailure(failure);
  };
  // A write on every rank (its piece of a frame): the lowest failing rank's reason stops all.
  auto writingOnEveryRank = [&](auto&& write) {
    std::string failure;
    try {
      write();
    } catch (const std::exception& e) {
      failure = "rank " + std::to_string(comm->rank()) + ": " + e.what();
    }
    if (comm->firstNonEmpty(failure) >= 0) throw OutputWriteFailure(failure);
  };
  auto flushSeries = [&] { writing([&] { series.flush(); }); };
  long lastFrameStep = -1;
  double nextFrameTime = out.everyTime;
  auto writeFrame = [&] {
    solver.synchronize();
    if (!out.fields.empty() && lastFrameStep != solver.stepCount()) {
      const auto& fields = setup.output.fields;
      if (!comm) {
        const auto hourglassError = hourglassErrorField(setup, solver, fields);
        writing([&] { vtu->write(makeFrame(setup, solver, fields, &hourglassError)); });
      } else {
        const auto hourglassError = hourglassErrorField(setup, solver, fields, false);
        const Frame piece =
            makeFrame(setup, solver, fields, &hourglassError, solver.ownedParticles());
        writingOnEveryRank([&] { vtu->writePiece(piece, comm->rank()); });
        writing([&] { vtu->addPieces(piece, comm->size(), true); });
        if (!root) vtu->addPieces(piece, comm->size(), false);  // counts it
      }
    }
    lastFrameStep = solver.stepCount();
    flushSeries();
  };

  RunSummary summary;
  summary.timeStep = solver.timeStep();
  summary.stableStep = solver.stableStepRule();
  summary.spectralStep = solver.spectralStep();
  RunGuard<D> guard(setup, solver);  // the stability guards (Guards.hpp)
  if (resume) {
    // The output as it was at the checkpoint: later rows and frames (written before the stop)
    // are dropped, so the continuation has neither duplicates nor gaps.
    const OutputProgress& o = resume->output;
    series.resume(o);
    if (vtu) vtu->resume(o.frames, root);
    lastFrameStep = o.lastFrameStep;
    nextFrameTime = o.nextFrameTime;
    guard.resume(resume->guard);
    summary.restartedAtStep = resume->solver.steps;
    if (comm) comm->barrier();  // rank 0 has removed later frames before any rank writes one
  }

  CheckpointSchedule schedule(dir, setup.name, setup.checkpoint);
  // The series are flushed first, so that the files hold every row the checkpoint counts.
  auto saveCheckpoint = [&](const NewtonSolver<D>* newton) {
    solver.synchronize();
    flushSeries();
    Checkpoint<D> c;
    c.origin = options.origin;
    c.solver = solver.state();
    c.guard = guard.state();
    if (newton) c.newton = newton->state();
    c.output.nextFrameTime = nextFrameTime;
    c.output.lastFrameStep = lastFrameStep;
    series.countRows(c.output);
    if (vtu) c.output.frames = vtu->frames();
    const fs::path file = schedule.fileFor(solver.stepCount());
    writing([&] {
      writeCheckpoint(file, c);
      schedule.written();
    });
    summary.checkpoint = file;
    ++summary.checkpointsWritten;
  };
  // After a failed write: one attempt at a checkpoint, and a message saying what is left.
  auto outputFailed = [&](const OutputWriteFailure& failure, const NewtonSolver<D>* newton) {
    summary.outcome = RunOutcome::OutputFailed;
    std::ostringstream m;
    m << "writing the output failed at step " << solver.stepCount() << ", t = " << solver.time()
      << " s: " << failure.what() << " (disk full? no permission?). The run stopped; ";
    const fs::path previous = summary.checkpoint;
    try {
      saveCheckpoint(newton);
      m << "a checkpoint of this step was written to " << summary.checkpoint.string()
        << ": make room, then continue with --restart=" << summary.checkpoint.string();
    } catch (const OutputWriteFailure& again) {
      m << "no checkpoint could be written either (" << again.what() << ")";
      if (!previous.empty())
        m << "; the last one is " << previous.string() << " (--restart=" << previous.string()
          << ")";
    }
    summary.message = m.str();
  };

  // What every run reports at its end.
  bool stateRecorded = false;  // an unstable run reports the failing state, recorded before
  auto finish = [&] {
    solver.synchronize();
    summary.partition = solver.partition();
    summary.wallSeconds = std::chrono::duration<double>(Clock::now() - start).count();
    if (vtu) summary.pvd = vtu->pvdPath();
    summary.energies = series.energiesFile();
    summary.probes = series.probesFile();
    summary.reactions = series.reactionsFile();
    const auto& rules = setup.scene.prescriptions;
    for (std::size_t r = 0; r < rules.size(); ++r) {
      Vec3 R = Vec3::Zero();
      R.head<D>() = solver.reaction(r);
      summary.finalReactions.emplace_back(rules[r].name, R);
    }
    if (!stateRecorded) {
      summary.steps = solver.stepCount();
      summary.time = solver.time();
      summary.residual = solver.residualRatio();
      summary.energy = solver.energyBalance();
    }
    return summary;
  };
  auto interruptedMessage = [&] {
    std::ostringstream m;
    m << "stopped by signal " << int(stopSignal()) << " at step " << solver.stepCount()
      << ", t = " << solver.time() << " s: the output holds the state at that step";
    if (!summary.checkpoint.empty())
      m << "; continue with --restart=" << summary.checkpoint.string();
    return m.str();
  };

  if (run.newtonStatic()) {
    // Load steps to equilibrium: one series row and one frame per converged step.
    NewtonSolver<D> newton(setup.scene, solver, run.newton, setup.coarsen, setup.solver);
    if (resume) {
      if (!resume->newton)
        throw CheckpointError("the checkpoint holds no Newton state (written by a damped run)");
      newton.resume(*resume->newton);
    }
    try {
      if (!resume) {
        recordSeries();
        writeFrame();
      }
      newton.run([&] {
        recordSeries();
        writeFrame();
        if (stopRequested()) {
          saveCheckpoint(&newton);
          return false;
        }
        if (schedule.due(newton.statistics().loadSteps)) saveCheckpoint(&newton);
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
      try {
        recordSeries();
        writeFrame();
      } catch (const OutputWriteFailure& f) {
        outputFailed(f, nullptr);
      }
    } catch (const OutputWriteFailure& f) {
      outputFailed(f, &newton);
    }
    if (options.progress) std::fprintf(stderr, "\r\033[K");
    summary.newton = newton.statistics();
    return finish();
  }

  auto lastProgress = Clock::now();
  // The CSV series reach the disk at least every flushSeconds of wall time, so a run that is
  // killed leaves its series up to then (frames flush them too).
  auto lastFlush = Clock::now();
  const auto flushInterval = std::chrono::duration<double>(out.flushSeconds);
  const double endTime = run.endTime * (1.0 - 1e-12);
  // What depends on a signal or a wall clock is rank 0's view, shared every step, so that all
  // ranks stop, write and check at the same step: 0 stop requested, 1 progress line due,
  // 2 series flush due, 3 checkpoint due (its wall-time interval; the step interval is common).
  auto agreed = [&](long step) {
    std::array<double, 4> due = {
        stopRequested() ? 1.0 : 0.0,
        options.progress && Clock::now() - lastProgress > std::chrono::milliseconds(500) ? 1.0
                                                                                         : 0.0,
        Clock::now() - lastFlush > flushInterval ? 1.0 : 0.0, schedule.due(step) ? 1.0 : 0.0};
    if (comm) {
      if (!root) due = {due[0], 0.0, 0.0, 0.0};
      comm->max(due.data(), 4);
    }
    return std::array<bool, 4>{due[0] > 0, due[1] > 0, due[2] > 0, due[3] > 0};
  };
  try {
    if (!resume) {
      recordSeries();
      writeFrame();
    }
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
      const std::array<bool, 4> due = agreed(solver.stepCount() + 1);
      if (due[0]) {
        // A checkpoint of a healthy state only: the guards look at it first.
        summary.instability = guard.check();
        if (summary.instability) {
          summary.outcome = RunOutcome::Unstable;
          break;
        }
        saveCheckpoint(nullptr);
        summary.outcome = RunOutcome::Interrupted;
        summary.message = interruptedMessage();
        break;
      }
      solver.step();
      const long step = solver.stepCount();
      const bool checkStep = step % run.checkEvery == 0;
      if (checkStep) {
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
        if (due[2]) {
          flushSeries();
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
      // A checkpoint holds a state the guards have passed: a good one to continue from.
      if (due[3]) {
        if (!checkStep && (summary.instability = guard.check())) {
          summary.outcome = RunOutcome::Unstable;
          break;
        }
        saveCheckpoint(nullptr);
      }
      if (due[1]) {
        lastProgress = Clock::now();
        solver.synchronize();
        const double wall = std::chrono::duration<double>(lastProgress - start).count();
        const EnergyBalance e = solver.energyBalance();
        std::fprintf(stderr, "\r\033[Kstep %ld  t = %.4g s of %.4g  dt = %.3g  ", step,
                     solver.time(), run.endTime, solver.timeStep());
        if (run.quasiStatic)
          std::fprintf(stderr, "residual %.3g (target %.3g)  ", solver.residualRatio(),
                       run.tolerance);
        const double eta = wall * (run.endTime - solver.time()) / std::max(solver.time(), 1e-300);
        std::fprintf(stderr, "ETA %s%.0f s  E_kin %.3g  E_strain %.3g",
                     run.quasiStatic ? "<= " : "", eta, e.kinetic, e.strain);
        std::fflush(stderr);
      }
    }
    if (options.progress) std::fprintf(stderr, "\r\033[K");
    if (summary.outcome != RunOutcome::Unstable) {
      recordSeries();
      writeFrame();
    } else {
      // The failing state's numbers for the record, then its frames (which leave the solver
      // in the last good state).
      solver.synchronize();
      flushSeries();
      summary.steps = solver.stepCount();
      summary.time = solver.time();
      summary.residual = solver.residualRatio();
      summary.energy = solver.energyBalance();
      stateRecorded = true;
      try {
        guard.writeFrames(*summary.instability);
      } catch (const std::exception& e) {
        summary.message =
            std::string("the frames of the instability could not be written: ") + e.what();
      }
    }
  } catch (const OutputWriteFailure& failure) {
    if (options.progress) std::fprintf(stderr, "\r\033[K");
    outputFailed(failure, nullptr);
  }
  return finish();
}

}  // namespace tlsph
