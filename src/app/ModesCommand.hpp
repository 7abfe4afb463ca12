// `tlsph modes SCENE.ini`: the lowest natural modes about the reference state (or, with
// --about=final, about the state a run of the scene ends in), the zero-energy-mode count against
// the rigid-body motions the conditions leave free, and each mode's hourglass content; mode
// shapes as a VTU series (one frame per mode) and a CSV table.
#pragma once

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <numeric>
#include <string>

#include "app/RunSimulation.hpp"
#include "modes/ModalAnalysis.hpp"
#include "output/CsvSeries.hpp"
#include "output/VtuSeriesWriter.hpp"
#include "scene/SceneSetup.hpp"

namespace tlsph {

struct ModesOptions {
  ModalSettings settings;
  bool aboutFinalState = false;  // run the scene first
  RunOptions run;
};

// Returns the exit status: 0, or 5 when zero-energy modes other than rigid-body motions exist.
template <int D>
int runModes(SceneSetup<D>& setup, const ModesOptions& options) {
  namespace fs = std::filesystem;
  if (options.aboutFinalState) {
    const RunSummary s = runSimulation(setup, options.run, [](const Solver<D>&) {});
    std::cout << "ran the scene to t = " << s.time << " s (" << s.steps
              << " steps); modes about its final state\n";
  }
  Solver<D> solver(setup.scene, setup.solver);
  const ModalResult<D> r = computeModes(setup.scene, solver, options.settings);
  const auto& p = setup.scene.particles;
  const bool penalty = setup.scene.hourglassCoefficient != 0.0;

  std::cout << "modes        " << r.modes.size() << " lowest of K phi = omega^2 M phi about the "
            << (options.aboutFinalState ? "final" : "reference") << " state, "
            << D *
                   [&] {
                     Index free = 0;
                     for (Index i = 0; i < p.size(); ++i)
                       free += p.motion[i] == Motion::Free;
                     return free;
                   }()
            << " unknowns; shift-invert Lanczos (Spectra), " << r.solves
            << " solves by conjugate gradients (" << r.krylovIterations
            << " iterations) preconditioned by " << r.linearSolver << "\n";
  std::cout << "hourglass    alpha = " << setup.scene.hourglassCoefficient
            << (penalty ? "" : " (penalty off)") << "\n\n";
  std::cout << "  mode   frequency [Hz]      omega^2 [1/s^2]   penalty share   hourglass content\n";
  for (std::size_t m = 0; m < r.modes.size(); ++m) {
    const Mode<D>& mode = r.modes[m];
    char line[160];
    std::snprintf(line, sizeof line, "  %4zu   %14s   %18.6g   %13.4f   %17.4f\n", m + 1,
                  mode.zero ? "0 (zero mode)" : std::to_string(mode.frequency).c_str(),
                  mode.eigenvalue, mode.penaltyShare, mode.hourglassContent);
    std::cout << line;
  }
  std::cout << "\nzero modes   " << r.zeroModes << " (omega^2 below "
            << options.settings.zeroThreshold << " x " << r.eigenvalueScale
            << "); the conditions leave " << r.expectedRigidModes << " rigid-body motion(s) free\n";
  int status = 0;
  if (r.zeroModes > r.expectedRigidModes) {
    std::cout << "SPURIOUS     " << r.zeroModes - r.expectedRigidModes
              << " zero-energy mode(s) are not rigid-body motions: hourglass modes the "
                 "discretisation does not resist"
              << (penalty ? "; raise [hourglass] alpha" : "; set [hourglass] alpha (e.g. 10)")
              << "\n";
    status = 5;
  }
  if (static_cast<int>(r.modes.size()) == r.zeroModes)
    std::cout << "note         every mode found is a zero mode: ask for more with --count\n";
  // The modes most made of hourglass, highest first.
  std::vector<std::size_t> order(r.modes.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return r.modes[a].hourglassContent > r.modes[b].hourglassContent;
  });
  std::cout << "highest hourglass content:";
  for (std::size_t k = 0; k < std::min<std::size_t>(5, order.size()); ++k)
    std::cout << " mode " << order[k] + 1 << " (" << std::setprecision(3)
              << r.modes[order[k]].hourglassContent << ")";
  std::cout << std::setprecision(6) << "\n";

  const fs::path dir = setup.output.directory;
  fs::create_directories(dir);
  CsvSeries table(dir / "modes.csv", {"mode", "frequency", "eigenvalue", "zero", "penalty_share",
                                      "hourglass_content"});
  table.setPreamble({"tlsph modes of " + setup.name + " from " + setup.sourceFile,
                     "command: " + options.run.command,
                     "frequency in Hz, eigenvalue omega^2 in 1/s^2"});
  for (std::size_t m = 0; m < r.modes.size(); ++m) {
    const Mode<D>& mode = r.modes[m];
    table.append({double(m + 1), mode.frequency, mode.eigenvalue, mode.zero ? 1.0 : 0.0,
                  mode.penaltyShare, mode.hourglassContent});
  }
  table.flush();
  VtuSeriesWriter vtu(dir, setup.name + "_modes");
  for (std::size_t m = 0; m < r.modes.size(); ++m) {
    Frame frame;
    frame.time = double(m + 1);  // the mode number: ParaView steps through the modes
    frame.step = static_cast<long>(m + 1);
    frame.points.resize(p.size());
    PointField shape{"mode_shape", 3, std::vector<double>(3 * p.size(), 0.0)};
    for (Index i = 0; i < p.size(); ++i) {
      frame.points[i] = {0.0, 0.0, 0.0};
      const Vec<D> x = p.currentPosition(i);
      for (int a = 0; a < D; ++a) {
        frame.points[i][a] = x[a];
        shape.values[3 * i + a] = r.modes[m].shape[i][a];
      }
    }
    frame.fields.push_back(std::move(shape));
    frame.flags.push_back(PointFlags{"ghost", setup.ghost});
    vtu.write(frame);
  }
  std::cout << "wrote        " << (dir / "modes.csv").string() << "\n"
            << "wrote        " << vtu.pvdPath().string()
            << " (one frame per mode; ParaView: Warp By Vector on mode_shape)\n";
  return status;
}

}  // namespace tlsph
