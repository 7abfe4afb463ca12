// tlsph: total-Lagrangian SPH for elastic solids.
//   tlsph run SCENE.ini [--section.key=value ...]
//   tlsph check SCENE.ini [--section.key=value ...]
//   tlsph compare RUN FEM.vtu [options]
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "app/Checkpoint.hpp"
#include "app/CheckpointSchedule.hpp"
#include "app/CompareCommand.hpp"
#include "app/ModesCommand.hpp"
#include "app/OutputDirectory.hpp"
#include "app/RunRecord.hpp"
#include "app/RunSimulation.hpp"
#include "scene/Config.hpp"
#include "scene/InputError.hpp"
#include "scene/SceneBuilder.hpp"
#include "model/Errors.hpp"
#include "execution/Threads.hpp"

#ifdef TLSPH_HAVE_MPI
#include <mpi.h>

#include "distributed/MpiCommunicator.hpp"
#endif

namespace {

constexpr const char* kVersion = "0.1.0";

constexpr const char* kUsage = R"(tlsph - total-Lagrangian SPH for elastic solids

usage:
  tlsph run   SCENE.ini [--section.key=value ...]   run a scene
  tlsph check SCENE.ini [--section.key=value ...]   validate and print the set-up, do not run
  tlsph modes SCENE.ini [--count=N] [--about=final] [--section.key=value ...]
                                                    lowest natural modes, zero-energy modes
                                                    and their hourglass content (docs/modes.md)
  tlsph compare RUN FEM.vtu [options]               errors against an FEM solution, field by
                                                    field (tlsph compare --help)
  tlsph --help | --version

Any key of the scene file can be overridden on the command line, e.g.
  tlsph run examples/cantilever.ini --time.end=0.5 --scene.dx=0.025
The scene format is documented in docs/scene-format.md.

run options:
  --progress / --no-progress   live progress line (default: on when stderr is a terminal
                               and CI is not set)
  --overwrite                  replace the output of an earlier run in the output directory
                               (without it such a directory is refused)
  --restart=CHECKPOINT         continue the run from a checkpoint (a file written under
                               OUTPUT/checkpoints/, or 'latest'); the scene must be the same
                               ([checkpoint] settings may differ) and the result is bit for
                               bit that of the uninterrupted run (any thread count)

exit status: 0 finished (or a static run converged), 1 bad input or set-up, 3 a static
run did not converge, 4 the run went unstable (a [guard] check failed: the message names
step, particle, quantity and likely cause; NAME_last_good.vtu and NAME_failed.vtu are
written), 5 (modes) zero-energy modes other than rigid-body motions, 6 an output file could
not be written (disk full, no permission: the message says which, and where the checkpoint
written on the way out is), 130 / 143 stopped by SIGINT (Ctrl-C) / SIGTERM: a checkpoint,
the series, a frame and summary.json hold the state at the step it stopped (a second signal
ends the program at once).
)";

using namespace tlsph;
namespace fs = std::filesystem;

struct RunFlags {
  bool overwrite = false;
  std::string restart;  // checkpoint file, "latest", or empty
  std::string sceneFile;
  std::vector<std::string> overrides;
};

template <int D>
void printSetup(const SceneSetup<D>& setup, const Solver<D>& solver) {
  const auto& p = setup.scene.particles;
  const NeighbourStats nb = solver.neighbourStats();
  Index ghosts = 0;
  for (Index i = 0; i < p.size(); ++i)
    ghosts += setup.ghost[i];
  std::cout << "scene        " << setup.name << " (" << D << "D" << (D == 2 ? ", plane strain" : "")
            << ") from " << setup.sourceFile << "\n"
            << "particles    " << p.size() << " (" << p.size() - ghosts << " body, " << ghosts
            << " ghost), dx = " << setup.dx << " m\n"
            << "neighbours   min " << nb.min << ", mean " << nb.mean << ", max " << nb.max
            << " (kernel " << kernelName(setup.scene.kernel)
            << ", H = " << setup.scene.supportRadius
            << " m = " << setup.scene.supportRadius / setup.dx << " dx, "
            << gradientCorrectionName(setup.scene.gradientCorrection) << " gradient correction, "
            << (setup.scene.quadrature == Quadrature::Taylor ? "Taylor-corrected" : "nodal")
            << " quadrature)\n"
            << "hourglass    alpha = " << setup.scene.hourglassCoefficient
            << (setup.scene.hourglassCoefficient == 0
                    ? std::string(" (off)")
                    : std::string(", form ") + hourglassFormName(setup.scene.hourglassForm) +
                          (setup.scene.hourglassForm == HourglassForm::Energy
                               ? std::string(", on the ") +
                                     hourglassGradientName(setup.scene.hourglassGradient) + " F"
                               : std::string()))
            << "\n";
  if (setup.scene.viscosity.enabled())
    std::cout << "viscosity    artificial (6.77): linear q1 = " << setup.scene.viscosity.linear
              << ", quadratic q2 = " << setup.scene.viscosity.quadratic << "\n";
  for (std::size_t m = 0; m < setup.scene.materials.size(); ++m) {
    const auto& mat = setup.scene.materials[m];
    const auto& c = elasticConstants(mat);
    std::cout << "material     " << setup.materialNames[m] << ": " << materialName(mat)
              << ", rho0 = " << density(mat) << ", E = " << c.youngsModulus
              << ", nu = " << c.poissonRatio << ", wave speed " << waveSpeed(mat) << " m/s\n";
  }
  for (const auto& line : setup.conditions)
    std::cout << "condition    " << line << "\n";
  if (setup.scene.damping.any())
    std::cout << "damping      viscous " << setup.scene.damping.viscous << " 1/s, kinetic "
              << (setup.scene.damping.kinetic ? "on" : "off") << "\n";
  for (const auto& probe : setup.probes)
    std::cout << "probe        " << probe.name << " at (" << probe.point.transpose() << "), "
              << (probe.method == ProbeMethod::Nearest ? "nearest particle"
                                                       : "kernel-interpolated, first order")
              << "\n";
  if (setup.run.newtonStatic()) {
    const double end = solver.rampEnd();
    std::cout << "static       Newton-Raphson, " << setup.run.newton.loadSteps
              << " load step(s) to the end of the ramps (t = " << end
              << " s), stop when residual < " << setup.run.tolerance << "; preconditioner "
              << newtonPreconditionerName(setup.run.newton.preconditioner);
    if (setup.run.newton.preconditioner == NewtonPreconditioner::Auto)
      std::cout << " (multigrid from " << setup.run.newton.autoMultigridUnknowns
                << " unknowns unless a Poisson ratio >= " << setup.run.newton.autoPoissonLimit
                << ", else cholesky)";
    std::cout << "\n";
  }
  const double steps = setup.run.endTime / solver.timeStep();
  std::cout << "time         dt = " << solver.timeStep() << " s (CFL " << setup.solver.cfl
            << "), end " << setup.run.endTime << " s, " << (setup.run.quasiStatic ? "at most " : "")
            << static_cast<long>(std::ceil(steps)) << " steps"
            << (setup.run.quasiStatic
                    ? ", static: stop when residual < " + std::to_string(setup.run.tolerance)
                    : std::string())
            << "\n";
  {
    // What sets the step: dt = C_cfl dx / sqrt(c^2 + c_hg^2) at the limiting particle.
    const StableStep& rule = solver.stableStepRule();
    const Vec<D> X = p.referencePosition[rule.particle];
    std::cout << "time step    "
              << (setup.solver.timeStep > 0.0 ? "[time] dt given; the rule gives " : "rule: ")
              << rule.dt << " s = CFL x dx / c_eff at particle " << rule.particle << " ("
              << X.transpose() << "): dx = " << rule.dx
              << " m, material wave speed c = " << rule.waveSpeed << " m/s";
    if (rule.hourglassSpeed > 0.0)
      std::cout << ", hourglass springs add c_hg = " << rule.hourglassSpeed
                << " m/s (c_eff = " << rule.hourglassFactor() << " c)";
    std::cout << "; limited by the "
              << (rule.hourglassSpeed > rule.waveSpeed ? "hourglass penalty"
                                                       : "material wave speed")
              << "\n";
  }
  std::cout << "output       " << setup.output.directory << "/";
  if (setup.output.fields.empty()) {
    std::cout << " (CSV only)\n";
  } else {
    std::cout << setup.name << ".pvd with";
    for (const auto& f : setup.output.fields)
      std::cout << " " << f;
    std::cout << "\n";
  }
  const OutputEstimate e = estimateOutput(setup, solver.timeStep());
  std::cout << "output size  at most " << byteText(e.total()) << ": " << e.frames << " frames of "
            << byteText(e.frameBytes) << " (uncompressed), " << e.seriesRows << " series rows ("
            << byteText(e.seriesBytes) << "), " << e.checkpointsKept << " checkpoint(s) of "
            << byteText(e.checkpointBytes) << " kept";
  std::error_code noSpace;
  fs::path existing = setup.output.directory;
  while (!existing.empty() && !fs::exists(existing, noSpace))
    existing = existing.parent_path();
  const auto space = fs::space(existing.empty() ? fs::path(".") : existing, noSpace);
  if (!noSpace) std::cout << "; " << byteText(double(space.available)) << " free there";
  std::cout << "\n";
  const CheckpointSettings& ck = setup.checkpoint;
  std::cout << "checkpoints  ";
  if (ck.everySteps > 0)
    std::cout << "every " << ck.everySteps << (setup.run.newtonStatic() ? " load" : "")
              << " steps, ";
  if (ck.everySeconds > 0) std::cout << "every " << ck.everySeconds << " s of wall time, ";
  std::cout << "on SIGINT/SIGTERM and on a failed write; the newest " << ck.keep << " kept in "
            << setup.output.directory << "/checkpoints/\n";
}

// Warnings only the solver's set-up can give (added to the scene's, for summary.json).
template <int D>
void addSolverWarnings(SceneSetup<D>& setup, const Solver<D>& solver, const std::string& command) {
  const FallbackSummary& fallback = solver.linearFallback();
  if (fallback.count == 0) return;
  const Index i = fallback.first;
  std::ostringstream w;
  w << setup.sourceFile << ": [kernel] correction: " << fallback.count << " of "
    << setup.scene.particles.size() << " particles (e.g. particle " << i << " at ("
    << setup.scene.particles.referencePosition[i].transpose() << ") with " << fallback.neighbours
    << " neighbours) have too few neighbours on two levels for the quadratic correction's fit "
       "(an acute corner, a strip two particles thick); they use the linear correction (6.69), "
       "exact for affine fields only. Raise [kernel] support (2.3 serves Cook's membrane) to "
       "use the quadratic one everywhere";
  setup.warnings.push_back(w.str());
  std::cerr << command << ": warning: " << w.str() << "\n";
}

// What a checkpoint records to recognise its run: version, scene text, overrides, settings.
CheckpointOrigin runOrigin(const Config& config, const RunFlags& flags, int threads) {
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
    addSolverWarnings(setup, solver, command);
    printSetup(setup, solver);
    return 0;
  }
  const int threads = maxThreads();
  RunOptions options;
  options.progress = progress;
  options.command = command;
  options.origin = runOrigin(config, flags, threads);
  options.origin.particles = particleDigest<D>(setup.scene.particles.referencePosition);
  options.comm = comm;

  std::optional<Checkpoint<D>> resume;
  if (!flags.restart.empty()) {
    const fs::path file = flags.restart == "latest"
                              ? CheckpointSchedule::latest(setup.output.directory, setup.name)
                              : fs::path(flags.restart);
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
    if (n.krylovIterations > 0) std::cout << ", " << n.krylovIterations << " CG iterations";
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

}  // namespace

#ifdef TLSPH_HAVE_MPI
// MPI for a process started by mpirun; finalised on the way out, whatever the path.
struct MpiSession {
  std::unique_ptr<MpiCommunicator> comm;  // null unless more than one rank
  bool initialised = false;
  MpiSession(int& argc, char**& argv) {
    if (!launchedByMpi()) return;
    int provided = 0;
    MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
    initialised = true;
    int size = 1;
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    if (size > 1) comm = std::make_unique<MpiCommunicator>(MPI_COMM_WORLD);
  }
  ~MpiSession() {
    comm.reset();  // frees its communicators before MPI goes
    if (initialised) MPI_Finalize();
  }
};
#endif

int tlsphMain(int argc, char** argv, Communicator* comm);

int main(int argc, char** argv) {
#ifdef TLSPH_HAVE_MPI
  MpiSession mpi(argc, argv);
  Communicator* comm = mpi.comm.get();
  // Rank 0 speaks for the run: the others run silently (their messages would repeat its own).
  if (comm && comm->rank() != 0) {
    std::cout.setstate(std::ios::failbit);
    std::cerr.setstate(std::ios::failbit);
  }
  return tlsphMain(argc, argv, comm);
#else
  return tlsphMain(argc, argv, nullptr);
#endif
}

int tlsphMain(int argc, char** argv, Communicator* comm) {
  std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty() || args[0] == "--help" || args[0] == "-h" || args[0] == "help") {
    std::cout << kUsage;
    return args.empty() ? 1 : 0;
  }
  if (args[0] == "--version") {
    std::cout << "tlsph " << kVersion << "\n";
    return 0;
  }
  const std::string verb = args[0];
  if (verb == "compare") return runCompare({args.begin() + 1, args.end()});
  if ((verb != "run" && verb != "check" && verb != "modes") || args.size() < 2) {
    std::cerr << "tlsph: expected 'run SCENE.ini', 'check SCENE.ini', 'modes SCENE.ini' or "
                 "'compare RUN FEM.vtu'; see tlsph --help\n";
    return 1;
  }
  const char* ci = std::getenv("CI");
  bool progress = isatty(STDERR_FILENO) && !(ci && *ci) && (!comm || comm->rank() == 0);
  std::vector<std::string> overrides;
  std::string command = "tlsph";
  for (const auto& a : args)
    command += " " + a;
  ModesOptions modes;
  RunFlags flags;
  flags.sceneFile = args[1];
  for (std::size_t k = 2; k < args.size(); ++k) {
    if (args[k] == "--progress") {
      progress = true;
    } else if (verb == "run" && args[k] == "--overwrite") {
      flags.overwrite = true;
    } else if (verb == "run" && (args[k].rfind("--restart=", 0) == 0 || args[k] == "--restart")) {
      std::string value;
      if (args[k] == "--restart") {
        if (k + 1 == args.size()) {
          std::cerr << "tlsph: run: --restart expects a checkpoint file or 'latest'\n";
          return 1;
        }
        value = args[++k];
      } else {
        value = args[k].substr(10);
      }
      if (value.empty()) {
        std::cerr << "tlsph: run: --restart expects a checkpoint file or 'latest'\n";
        return 1;
      }
      flags.restart = value;
    } else if (args[k] == "--no-progress") {
      progress = false;
    } else if (verb == "modes" && args[k].rfind("--count=", 0) == 0) {
      const std::string value = args[k].substr(8);
      char* end = nullptr;
      const long count = std::strtol(value.c_str(), &end, 10);
      if (value.empty() || *end != '\0' || count < 1 || count > 10000) {
        std::cerr << "tlsph: modes: --count expects a whole number from 1 to 10000, got '" << value
                  << "'\n";
        return 1;
      }
      modes.settings.count = static_cast<int>(count);
    } else if (verb == "modes" && args[k].rfind("--about=", 0) == 0) {
      const std::string value = args[k].substr(8);
      if (value != "reference" && value != "final") {
        std::cerr << "tlsph: modes: --about expects reference or final, got '" << value << "'\n";
        return 1;
      }
      modes.aboutFinalState = value == "final";
    } else {
      overrides.push_back(args[k]);
    }
  }
  flags.overrides = overrides;
  if (comm && comm->rank() != 0) progress = false;
  try {
    const Config config = Config::read(args[1], overrides);
    const int d = sceneDimension(config);
    if (verb == "modes") {
      if (comm)
        throw std::runtime_error("tlsph modes runs on one rank only: start it without mpirun");
      modes.run.command = command;
      modes.run.progress = progress;
      modes.run.origin = runOrigin(config, flags, maxThreads());
      if (d == 2) {
        SceneSetup<2> setup = buildScene<2>(config);
        return runModes<2>(setup, modes);
      }
      SceneSetup<3> setup = buildScene<3>(config);
      return runModes<3>(setup, modes);
    }
    return d == 2 ? runOrCheck<2>(config, verb == "run", progress, command, flags, comm)
                  : runOrCheck<3>(config, verb == "run", progress, command, flags, comm);
  } catch (const InputError& e) {
    std::cerr << "tlsph: " << e.what() << "\n";
  } catch (const SetupError& e) {
    std::cerr << "tlsph: " << args[1] << ": set-up error: " << e.what() << "\n";
  } catch (const std::exception& e) {
    std::cerr << "tlsph: " << e.what() << "\n";
  }
  return 1;
}
