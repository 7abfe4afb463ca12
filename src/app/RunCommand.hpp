// `tlsph run` and `tlsph check`: build the scene, then either print its set-up or run it
// (from a checkpoint if asked), write the run record and report how the run ended. The return
// value is the program's exit status (tlsph --help lists them).
#pragma once

#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "app/Checkpoint.hpp"
#include "app/CheckpointSchedule.hpp"
#include "app/OutputDirectory.hpp"
#include "app/RunRecord.hpp"
#include "app/RunSimulation.hpp"
#include "app/SetupReport.hpp"
#include "app/StopRequest.hpp"
#include "execution/Threads.hpp"
#include "scene/Config.hpp"
#include "scene/SceneBuilder.hpp"

namespace tlsph {

// The program's version (tlsph --version), recorded in checkpoints and summary.json: a
// checkpoint of another version is refused.
inline constexpr const char* kVersion = "0.1.0";

// The command line of `tlsph run` beyond the scene's own keys.
struct RunFlags {
  bool overwrite = false;
  std::string restart;  // checkpoint file, "latest", or empty
  std::string sceneFile;
  std::vector<std::string> overrides;
};

// What a checkpoint records to recognise its run: version, scene text, overrides, settings.
inline CheckpointOrigin runOrigin(const Config& config, const RunFlags& flags, int threads) {
  CheckpointOrigin origin;
  origin.version = kVersion;
  origin.sceneFile = flags.sceneFile;
  std::ifstream in(flags.sceneFile, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  origin.sceneText = text.str();
  origin.overrides = flags.overrides;
  origin.settings = config.settings();
  origin.threads = threads;
  return origin;
}

// Runs `action` on rank 0 only; an exception there is thrown on every rank (with its message),
// so that no rank goes on alone into the run's collectives.
template <class Action>
void onRoot(Communicator* comm, Action&& action) {
  if (!comm) return action();
  std::string failure;
  if (comm->rank() == 0) {
    try {
      action();
    } catch (const std::exception& e) {
      failure = e.what();
      if (failure.empty()) failure = "unknown error";
    }
  }
  comm->broadcast(failure);
  if (!failure.empty()) throw std::runtime_error(failure);
}

template <int D>
int runOrCheck(const Config& config, bool run, bool progress, const std::string& command,
               const RunFlags& flags, Communicator* comm) {
  SceneSetup<D> setup = buildScene<D>(config);
  for (const auto& warning : setup.warnings)
    std::cerr << command << ": warning: " << warning << "\n";
  if (!run) {
    Scene<D> copy = setup.scene;  // the check builds the solver's set-up without running
    Solver<D> solver(copy, setup.solver);
    applySpectralStep(setup, solver);
    addSolverWarnings(setup, solver, command);
    printSetup(setup, solver);
    return 0;
  }
  const int threads = maxThreads();
  RunOptions options;
  options.progress = progress;
  options.command = command;
  options.origin = runOrigin(config, flags, threads);
  options.origin.particles = particleDigest<D>(setup.scene.particles.referencePosition,
                                               setup.scene.particles.quadratureMoments());
  options.comm = comm;

  std::optional<Checkpoint<D>> resume;
  if (!flags.restart.empty()) {
    const std::filesystem::path file =
        flags.restart == "latest" ? CheckpointSchedule::latest(setup.output.directory, setup.name)
                                  : std::filesystem::path(flags.restart);
    const CheckpointReader reader(file);
    const std::string why = checkpointMismatch(readCheckpointOrigin(reader), kVersion,
                                               options.origin.settings, options.origin.particles);
    if (!why.empty())
      throw CheckpointError("cannot restart from checkpoint " + file.string() + ": " + why);
    resume = readCheckpoint<D>(reader);
    std::cout << "restart      from " << file.string() << " (step " << resume->solver.steps
              << ", t = " << resume->solver.time << " s)\n";
  }
  onRoot(comm, [&] {
    prepareOutputDirectory(setup.output.directory, setup.name, flags.overwrite, resume.has_value());
  });

  installStopHandlers();
  NeighbourStats neighbours;
  const RunSummary s = runSimulation(
      setup, options,
      [&](const Solver<D>& solver) {
        addSolverWarnings(setup, solver, command);
        printSetup(setup, solver);
        if (!resume)
          onRoot(comm, [&] {
            checkFreeSpace(setup.output.directory, estimateOutput(setup, solver.timeStep()));
          });
        neighbours = solver.neighbourStats();
      },
      resume ? &*resume : nullptr);
  const std::filesystem::path record =
      std::filesystem::path(setup.output.directory) / "summary.json";
  try {
    if (!comm || comm->rank() == 0)
      writeRunRecord(record, setup, neighbours, s, threads, command, kVersion);
  } catch (const std::exception& e) {
    std::cerr << "tlsph: cannot write " << record.string() << ": " << e.what() << "\n";
    if (s.outcome != RunOutcome::OutputFailed) return 6;
  }
  if (s.newton) {
    const NewtonStatistics& n = *s.newton;
    std::cout << "\nNewton       " << n.loadSteps << " load steps, " << n.iterations
              << " iterations";
    if (n.krylovIterations > 0)
      std::cout << ", " << n.krylovIterations
                << (n.linearSolver.starts_with("BiCGSTAB") ? " BiCGSTAB" : " CG") << " iterations";
    if (n.levels > 1)
      std::cout << ", " << n.factorisations << " preconditioner set-ups (" << n.linearSolver
                << "; coarsest matrix " << n.nonZeros << " stored entries, factor "
                << n.factorNonZeros << "); wall " << s.wallSeconds << " s: set-up "
                << n.factorisationSeconds;
    else
      std::cout << ", " << n.factorisations << " factorisations (" << n.linearSolver << ", "
                << n.nonZeros << " stored entries); wall " << s.wallSeconds << " s: assembly "
                << n.assemblySeconds << ", factorisation " << n.factorisationSeconds;
    std::cout << ", solves " << n.solveSeconds << " (" << threads
              << (threads == 1 ? " thread" : " threads") << ")\n";
  } else {
    std::cout << "\nsteps " << s.steps << ", simulated " << s.time << " s, wall " << s.wallSeconds
              << " s (" << double(setup.scene.particles.size()) * s.steps / s.wallSeconds
              << " particle-steps/s, ";
    if (s.partition.ranks > 1)
      std::cout << s.partition.ranks << " ranks x " << threads
                << (threads == 1 ? " thread" : " threads") << "; partition " << s.partition.method
                << ", " << s.partition.halo << " halo particles)\n";
    else
      std::cout << threads << (threads == 1 ? " thread" : " threads") << ")\n";
  }
  std::cout << "energy       kinetic " << s.energy.kinetic << ", strain " << s.energy.strain
            << ", hourglass " << s.energy.hourglass << ", external work " << s.energy.externalWork
            << ", damped " << s.energy.damped << "\n";
  if (!s.pvd.empty()) std::cout << "wrote        " << s.pvd.string() << "\n";
  std::cout << "wrote        " << s.energies.string() << "\n";
  if (!s.probes.empty()) std::cout << "wrote        " << s.probes.string() << "\n";
  if (s.instability) {
    std::cout << "wrote        " << s.instability->failedFrame.string() << "\n"
              << "wrote        " << s.instability->lastGoodFrame.string() << " (step "
              << s.instability->lastGoodStep << ", t = " << s.instability->lastGoodTime << " s)\n";
  }
  std::cout << "wrote        " << record.string() << "\n";
  if (!s.checkpoint.empty() && s.outcome != RunOutcome::OutputFailed)
    std::cout << "checkpoint   " << s.checkpoint.string() << " (" << s.checkpointsWritten
              << " written by this run)\n";
  if (!s.message.empty() && s.outcome != RunOutcome::OutputFailed) std::cout << s.message << "\n";
  switch (s.outcome) {
    case RunOutcome::Finished:
      std::cout << "finished\n";
      return 0;
    case RunOutcome::Converged:
      std::cout << "converged: residual " << s.residual << " < " << setup.run.tolerance << "\n";
      return 0;
    case RunOutcome::NotConverged:
      if (s.newton) {
        std::cout << "NOT converged (Newton): residual " << s.residual << "\n";
        return 3;
      }
      std::cout << "NOT converged: residual " << s.residual << " >= " << setup.run.tolerance
                << " at the end time; raise [time] end or the damping\n";
      return 3;
    case RunOutcome::Interrupted:
      std::cout << "interrupted\n";
      return 128 + int(stopSignal());
    case RunOutcome::OutputFailed:
      std::cout.flush();
      std::cerr << "tlsph: " << s.message << "\n";
      return 6;
    case RunOutcome::Unstable: {
      // tlsph: unstable at step N, t = T s: <quantity and value> at particle I (X = ...):
      //   likely <cause>
      std::cout.flush();
      const Instability& u = *s.instability;
      std::cerr << "tlsph: unstable at step " << u.step << ", t = " << u.time
                << " s: " << u.description;
      if (u.particle >= 0)
        std::cerr << " at particle " << u.particle
                  << " (X = " << guard_detail::vectorText(u.referencePosition) << ")";
      std::cerr << ":\n  " << u.cause << "\n";
      return 4;
    }
  }
  return 0;
}

}  // namespace tlsph
