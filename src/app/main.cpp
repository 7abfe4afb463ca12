// tlsph: total-Lagrangian SPH for elastic solids.
//   tlsph run SCENE.ini [--section.key=value ...]
//   tlsph check SCENE.ini [--section.key=value ...]
//   tlsph compare RUN FEM.vtu [options]
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "app/CompareCommand.hpp"
#include "app/ModesCommand.hpp"
#include "app/RunCommand.hpp"
#include "execution/Threads.hpp"
#include "model/Errors.hpp"
#include "scene/Config.hpp"
#include "scene/InputError.hpp"
#include "scene/SceneBuilder.hpp"

#ifdef TLSPH_HAVE_MPI
#include <mpi.h>

#include "distributed/MpiCommunicator.hpp"
#endif

namespace {

constexpr const char* kUsage = R"(tlsph - total-Lagrangian SPH for elastic solids

usage:
  tlsph run   SCENE.ini [--section.key=value ...]   run a scene
  tlsph check SCENE.ini [--section.key=value ...]   validate and print the set-up, do not run
  tlsph modes SCENE.ini [--count=N | --range=FMIN,FMAX] [--about=final]
        [--section.key=value ...]                   lowest natural modes (or those with a
                                                    frequency in [FMIN, FMAX] Hz), checked
                                                    complete by inertia (Sturm count), the
                                                    zero-energy modes counted by inertia, and
                                                    their hourglass content (docs/modes.md)
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
written), 5 (modes) zero-energy modes other than rigid-body motions, 7 (modes) the modes
found could not be shown to be all the eigenvalues below the highest (no list), 6 an output file could
not be written (disk full, no permission: the message says which, and where the checkpoint
written on the way out is), 130 / 143 stopped by SIGINT (Ctrl-C) / SIGTERM: a checkpoint,
the series, a frame and summary.json hold the state at the step it stopped (a second signal
ends the program at once).
)";

using namespace tlsph;

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
  bool countGiven = false;
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
      countGiven = true;
    } else if (verb == "modes" && args[k].rfind("--range=", 0) == 0) {
      const std::string value = args[k].substr(8);
      const std::size_t comma = value.find(',');
      auto number = [](const std::string& text, double& out) {
        char* end = nullptr;
        out = std::strtod(text.c_str(), &end);
        return !text.empty() && *end == '\0' && std::isfinite(out);
      };
      double low = 0.0, high = 0.0;
      if (comma == std::string::npos || !number(value.substr(0, comma), low) ||
          !number(value.substr(comma + 1), high) || low < 0.0 || high <= low) {
        std::cerr << "tlsph: modes: --range expects FMIN,FMAX in Hz, two numbers with "
                     "0 <= FMIN < FMAX, got '"
                  << value << "'\n";
        return 1;
      }
      modes.settings.band = true;
      modes.settings.lowHz = low;
      modes.settings.highHz = high;
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
  if (countGiven && modes.settings.band) {
    std::cerr << "tlsph: modes: --count and --range exclude each other: --count=N lists the N "
                 "lowest modes, --range=FMIN,FMAX every mode in the band\n";
    return 1;
  }
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
  } catch (const IncompleteModes& e) {
    std::cerr << "tlsph: " << args[1] << ": modes: " << e.what() << "\n";
    return 7;
  } catch (const SetupError& e) {
    std::cerr << "tlsph: " << args[1] << ": set-up error: " << e.what() << "\n";
  } catch (const std::exception& e) {
    std::cerr << "tlsph: " << e.what() << "\n";
  }
  return 1;
}
