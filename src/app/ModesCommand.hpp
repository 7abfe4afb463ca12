// `tlsph modes SCENE.ini`: the lowest natural modes (or those of a band) about the reference
// state (or, with --about=final, about the state a run of the scene ends in), checked complete
// by the inertia of K - s M, the zero-energy-mode count (by inertia) against the rigid-body
// motions the conditions leave free, and each mode's hourglass content; mode shapes as a VTU
// series (one frame per mode), a CSV table and a JSON record (modes.json).
#pragma once

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <numeric>
#include <sstream>
#include <string>
#include <vector>

#include "app/RunSimulation.hpp"
#include "io/AtomicFile.hpp"
#include "io/JsonText.hpp"
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

// The lines that say what the counts and the check are, for the console and modes.csv.
template <int D>
std::vector<std::string> modeCountLines(const ModalResult<D>& r, const ModalSettings& settings) {
  std::vector<std::string> lines;
  std::ostringstream o;
  o.precision(6);
  auto line = [&] {
    lines.push_back(o.str());
    o.str("");
  };
  const InertiaCheck& c = r.inertia;
  if (c.made) {
    o << "inertia      exact K " << c.exactK;
    if (c.exactK == "probed") o << " (" << c.probes << " products K v, " << c.groups << " groups)";
    o << ", " << c.kNonZeros << " entries in " << c.kSeconds
      << " s, |K v - apply| / |K v| = " << c.mismatch << "; L D L^T " << c.factorNonZeros
      << " entries, " << c.factorisations << " factorisations, " << c.seconds << " s";
    line();
    o << "check        " << c.below << " eigenvalue(s) below omega^2 = " << c.cut
      << (settings.band ? " (the band's upper edge)" : " (just above the highest mode listed)")
      << " by inertia, " << c.found << " found: complete (" << r.rounds << " Lanczos run(s))";
    line();
    o << "zero modes   " << r.zeroModes
      << " by inertia (eigenvalues below sigma_0 = " << settings.zeroShift << " x "
      << r.eigenvalueScale << " = " << r.zeroShift << "); the conditions leave "
      << r.expectedRigidModes << " rigid-body motion(s) free";
    line();
  } else {
    o << "inertia      not counted: " << c.why;
    line();
    o << "check        none: the list is what " << r.rounds
      << " Lanczos run(s) found, not shown complete";
    line();
    o << "zero modes   " << r.zeroModes
      << " among the modes found (omega^2 below sigma_0 = " << settings.zeroShift << " x "
      << r.eigenvalueScale << " = " << r.zeroShift << "); the conditions leave "
      << r.expectedRigidModes << " rigid-body motion(s) free";
    line();
  }
  if (settings.band) {
    o << "band         " << settings.lowHz << " to " << settings.highHz << " Hz: " << r.modes.size()
      << " mode(s) listed";
    if (r.inBand >= 0)
      o << ", " << r.inBand << " by inertia (count below the upper edge minus "
        << "count below the lower)";
    line();
  }
  return lines;
}

template <int D>
std::string modesRecord(const SceneSetup<D>& setup, const ModalResult<D>& r,
                        const ModesOptions& options) {
  const ModalSettings& s = options.settings;
  const InertiaCheck& c = r.inertia;
  std::ostringstream j;
  auto field = [&](const char* key, const std::string& value, bool last = false) {
    j << "  " << jsonText(key) << ": " << value << (last ? "\n" : ",\n");
  };
  auto number = [](double v) { return jsonNumber(v); };
  j << "{\n";
  field("scene", jsonText(setup.name));
  field("source", jsonText(setup.sourceFile));
  field("command", jsonText(options.run.command));
  field("about", jsonText(options.aboutFinalState ? "final" : "reference"));
  field("modes_listed", std::to_string(r.modes.size()));
  if (s.band) {
    field("band_hz", "[" + number(s.lowHz) + ", " + number(s.highHz) + "]");
    field("modes_in_band_by_inertia", r.inBand >= 0 ? std::to_string(r.inBand) : "null");
  } else {
    field("count", std::to_string(s.count));
  }
  field("frequencies_hz", [&] {
    std::string a = "[";
    for (std::size_t m = 0; m < r.modes.size(); ++m)
      a += (m ? ", " : "") + number(r.modes[m].frequency);
    return a + "]";
  }());
  field("zero_modes", std::to_string(r.zeroModes));
  field("zero_modes_counted_by", jsonText(r.zeroModesByInertia ? "inertia" : "threshold"));
  field("zero_shift", number(r.zeroShift));
  field("eigenvalue_scale", number(r.eigenvalueScale));
  field("rigid_body_modes", std::to_string(r.expectedRigidModes));
  field("spurious_zero_modes", std::to_string(std::max(0, r.zeroModes - r.expectedRigidModes)));
  field("inertia_counted", c.made ? "true" : "false");
  if (c.made) {
    field("exact_stiffness", jsonText(c.exactK));
    field("probe_products", std::to_string(c.probes));
    field("exact_stiffness_entries", std::to_string(c.kNonZeros));
    field("exact_stiffness_mismatch", number(c.mismatch));
    field("ldlt_entries", std::to_string(c.factorNonZeros));
    field("factorisations", std::to_string(c.factorisations));
    field("inertia_seconds", number(c.seconds));
    field("check_cut", number(c.cut));
    field("eigenvalues_below_cut", std::to_string(c.below));
    field("found_below_cut", std::to_string(c.found));
    field("complete", c.complete ? "true" : "false");
  } else {
    field("inertia_not_counted_because", jsonText(c.why));
  }
  field("lanczos_runs", std::to_string(r.rounds));
  field("solves", std::to_string(r.solves));
  field("cg_iterations", std::to_string(r.krylovIterations), true);
  j << "}\n";
  return j.str();
}

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

  std::cout << "modes        " << r.modes.size()
            << (options.settings.band ? " in the band" : " lowest")
            << " of K phi = omega^2 M phi about the "
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
  std::cout << "\n";
  const std::vector<std::string> counts = modeCountLines(r, options.settings);
  for (const auto& line : counts)
    std::cout << line << "\n";
  int status = 0;
  if (r.zeroModes > r.expectedRigidModes) {
    std::cout << "SPURIOUS     " << r.zeroModes - r.expectedRigidModes
              << " zero-energy mode(s) are not rigid-body motions: hourglass modes the "
                 "discretisation does not resist"
              << (penalty ? "; raise [hourglass] alpha" : "; set [hourglass] alpha (e.g. 10)")
              << "\n";
    status = 5;
  }
  if (!r.modes.empty() && r.modes.back().zero)
    std::cout << "note         every mode listed is a zero mode: ask for more with --count\n";
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
  std::vector<std::string> preamble = {"tlsph modes of " + setup.name + " from " + setup.sourceFile,
                                       "command: " + options.run.command,
                                       "frequency in Hz, eigenvalue omega^2 in 1/s^2"};
  preamble.insert(preamble.end(), counts.begin(), counts.end());
  table.setPreamble(preamble);
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
  writeTextAtomically(dir / "modes.json", {modesRecord(setup, r, options)}, "modes record");
  std::cout << "wrote        " << (dir / "modes.csv").string() << "\n"
            << "wrote        " << (dir / "modes.json").string() << "\n"
            << "wrote        " << vtu.pvdPath().string()
            << " (one frame per mode; ParaView: Warp By Vector on mode_shape)\n";
  return status;
}

}  // namespace tlsph
