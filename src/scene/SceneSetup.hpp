// Everything a scene file describes, ready to run: the Scene itself plus how to run it,
// what to write and where to probe.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "explicit/Solver.hpp"
#include "implicit/NewtonSolver.hpp"
#include "method/SurfaceStress.hpp"
#include "model/Scene.hpp"
#include "model/SurfacePatch.hpp"

namespace tlsph {

struct RunSettings {
  double endTime = 0.0;
  long maxSteps = 0;  // 0: no limit
  bool quasiStatic = false;
  double tolerance = 1e-4;  // out-of-balance force ratio at which a static run has converged
  long checkEvery = 50;     // steps between convergence and stability checks
  // How a static run finds equilibrium: explicit dynamics with damping until the residual is
  // small (damped), or Newton-Raphson on the tangent stiffness with load steps (newton).
  enum class StaticSolver { Damped, Newton };
  StaticSolver staticSolver = StaticSolver::Damped;
  NewtonSettings newton;
  bool newtonStatic() const { return quasiStatic && staticSolver == StaticSolver::Newton; }
};

struct OutputSettings {
  std::string directory;
  std::vector<std::string> fields;  // VTU point fields; empty: no VTU output
  long everySteps = 0;              // VTU frame every N steps (0: use everyTime)
  double everyTime = 0.0;           // VTU frame every T seconds of simulated time
  long seriesEverySteps = 0;        // energies/probes CSV row every N steps
  bool hourglassContent = false;    // energies.csv: the displacement field's hourglass content
  double flushSeconds = 10.0;       // CSV series written at least this often [s of wall time]
};

// Periodic checkpoints ([checkpoint]); a checkpoint is also written when a signal stops the run.
struct CheckpointSettings {
  long everySteps = 0;          // every N steps (Newton: load steps); 0: not by steps
  double everySeconds = 600.0;  // every T seconds of wall time; 0: not by time
  long keep = 2;                // the newest K are kept
};

// The run's stability guards ([guard]), evaluated every RunSettings::checkEvery steps.
struct GuardSettings {
  double minJacobian = 0.0;   // stop when det F <= this at a body particle
  double energyError = 0.05;  // stop when the energy books drift by this fraction of their
                              // scale, or the hourglass energy is that far below zero; 0: off
};

enum class ProbeMethod { Nearest, Kernel, Surface };

// A load on a surface probe's surface, as the traction it puts on the probe's particle at the
// full ramp: dead (per unit reference area) or a following pressure.
template <int D>
struct ProbeTraction {
  Ramp ramp;
  Vec<D> dead = Vec<D>::Zero();
  double followingPressure = 0.0;
};

template <int D>
struct Probe {
  std::string name;
  Vec<D> point = Vec<D>::Zero();
  ProbeMethod method = ProbeMethod::Nearest;
  std::vector<std::string> quantities;  // "displacement", "velocity"
  // Resolved at setup: the particles and weights whose combination is the probe value.
  std::vector<Index> particles;
  std::vector<double> weights;
  std::vector<Vec<D>> offsets;  // Kernel: point - X_J, for the first-order correction
  // Surface: the stress recovery's fit at the particle and the loads on its surface.
  std::string surfaceName;
  double fitRadius = 0.0;  // [m]
  std::optional<SurfaceStencil<D>> stencil;
  std::vector<ProbeTraction<D>> tractions;
};

template <int D>
struct SceneSetup {
  std::string name;
  std::string sourceFile;
  double dx = 0.0;
  // The scene rebuilt at `factor` times dx (the Newton solver's multigrid levels).
  SceneCoarsening<D> coarsen;
  Scene<D> scene;
  SolverSettings solver;
  RunSettings run;
  OutputSettings output;
  CheckpointSettings checkpoint;
  GuardSettings guard;
  std::vector<Probe<D>> probes;
  std::vector<std::string> materialNames;  // by material index
  std::vector<std::string> bodyNames;      // by body index
  std::vector<std::uint8_t> body;          // per particle: index into bodyNames
  std::vector<std::uint8_t> ghost;         // per particle: 1 for clamp ghosts
  std::map<std::string, std::vector<Index>> regions;
  // A mesh body's named surfaces (gmsh physical groups of dimension d - 1), by name.
  std::map<std::string, SurfacePatch<D>> surfaces;
  // Whether the body was read from a particle file or meshed from a CAD or mesh file rather
  // than filled on the lattice (no ghost clamps, no lattice neighbours).
  bool freeForm = false;
  // Whether the scene can be rebuilt at a coarser dx (the Newton solver's multigrid levels): not
  // a particle file, nor a mesh at a size of its own.
  bool coarsenable = true;
  // The first following pressure's section and the place of its `follow` key (a distributed
  // run refuses it); empty when the scene has none.
  std::string followingLoad, followingWhere;
  std::vector<std::string> conditions;  // one line per condition, for `tlsph check`
  std::vector<std::string> warnings;    // scene problems that do not stop a run
};

}  // namespace tlsph
