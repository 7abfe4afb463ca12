// The output directory of a run, checked before anything is written: that it can be created
// and written to, that it does not hold an earlier run's output (kept unless --overwrite), and
// that its file system has room for what the run plans to write (an estimate, printed by
// `tlsph check`).
#pragma once

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

#include "explicit/Solver.hpp"
#include "scene/SceneSetup.hpp"

namespace tlsph {

// The output directory cannot take this run's output; the message says why and what to do.
class OutputDirectoryError : public std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Bytes a run plans to write, at most (VTU frames counted uncompressed).
struct OutputEstimate {
  long frames = 0;
  double frameBytes = 0.0;  // one frame
  long seriesRows = 0;
  double seriesBytes = 0.0;      // all CSV series together
  double checkpointBytes = 0.0;  // one checkpoint
  long checkpointsKept = 0;
  double total() const {
    return frames * frameBytes + seriesBytes + checkpointBytes * (checkpointsKept + 1);
  }
};

template <int D>
OutputEstimate estimateOutput(const SceneSetup<D>& setup, double timeStep) {
  const OutputSettings& out = setup.output;
  const RunSettings& run = setup.run;
  const double n = static_cast<double>(setup.scene.particles.size());
  OutputEstimate e;
  // Steps (Newton: load steps; damped static: at most, the end time is an upper bound).
  const double steps = run.newtonStatic() ? double(run.newton.loadSteps)
                                          : std::ceil(run.endTime / std::max(timeStep, 1e-300));
  if (!out.fields.empty()) {
    double perFrame = run.newtonStatic()   ? steps
                      : out.everySteps > 0 ? steps / double(out.everySteps)
                                           : run.endTime / std::max(out.everyTime, 1e-300);
    e.frames = static_cast<long>(std::min(perFrame, 1e12)) + 2;  // the first and the last
    double components = 3.0;                                     // point coordinates
    for (const auto& f : out.fields)
      components += f == "displacement" || f == "velocity"       ? 3.0
                    : f == "cauchy_stress" || f == "first_piola" ? 9.0
                    : f == "flags"                               ? 3.0 / 8.0
                                                                 : 1.0;
    e.frameBytes = n * (8.0 * components + 17.0) + 4096.0;  // + vertex cells, header
  }
  double columns = 13.0 + (out.hourglassContent ? 1.0 : 0.0);
  for (const auto& probe : setup.probes)
    for (const auto& q : probe.quantities)
      columns += q == "cauchy_stress" ? 6.0 : double(D);
  columns += double(D * setup.scene.prescriptions.size()) + 2.0;
  e.seriesRows = static_cast<long>(
      std::min(run.newtonStatic() ? steps : steps / double(out.seriesEverySteps), 1e12) + 2);
  e.seriesBytes = e.seriesRows * columns * 24.0;
  // Displacement, velocity (and the force pass's velocity), the Newton preconditioner's F and,
  // when it may be the multigrid, its displacements and Taylor second gradients (D x D(D+1)/2).
  const bool multigrid =
      run.newtonStatic() && run.newton.preconditioner != NewtonPreconditioner::Cholesky;
  const double secondGradients =
      setup.scene.quadrature == Quadrature::Taylor ? D * D * (D + 1) / 2.0 : 0.0;
  e.checkpointBytes = n * D * 8.0 * (setup.scene.viscosity.enabled() ? 3.0 : 2.0) +
                      (run.newtonStatic() ? n * D * D * 8.0 : 0.0) +
                      (multigrid ? n * (D + secondGradients) * 8.0 : 0.0) + 65536.0;
  e.checkpointsKept = setup.checkpoint.keep;
  return e;
}

inline std::string byteText(double bytes) {
  char text[32];
  if (bytes < 1e6)
    std::snprintf(text, sizeof text, "%.0f kB", std::ceil(bytes / 1e3));
  else if (bytes < 1e9)
    std::snprintf(text, sizeof text, "%.1f MB", bytes / 1e6);
  else
    std::snprintf(text, sizeof text, "%.2f GB", bytes / 1e9);
  return text;
}

// Files of a run named `name` in its output directory (and directories of frame pieces):
// what --overwrite removes, and what marks the directory as holding a run.
inline std::vector<std::filesystem::path> runOutputFiles(const std::filesystem::path& dir,
                                                         const std::string& name) {
  namespace fs = std::filesystem;
  std::vector<fs::path> files;
  std::error_code status;
  if (!fs::is_directory(dir, status)) return files;
  // NAME_NNNNNN + suffix: a frame (.vtu), a distributed frame's index (.pvtu) or the
  // directory of its pieces ("").
  auto isFrame = [&](const std::string& f, const std::string& suffix) {
    const std::size_t stem = name.size() + 1;
    if (f.size() != stem + 6 + suffix.size() || f.compare(0, stem, name + "_") != 0 ||
        f.compare(stem + 6, suffix.size(), suffix) != 0)
      return false;
    return std::all_of(f.begin() + stem, f.begin() + stem + 6,
                       [](char c) { return c >= '0' && c <= '9'; });
  };
  for (const auto& entry : fs::directory_iterator(dir, status)) {
    const std::string f = entry.path().filename().string();
    if (entry.is_directory(status)
            ? isFrame(f, "")
            : f == "summary.json" || f == "energies.csv" || f == "probes.csv" ||
                  f == "reactions.csv" || f == name + ".pvd" || f == name + "_last_good.vtu" ||
                  f == name + "_failed.vtu" || isFrame(f, ".vtu") || isFrame(f, ".pvtu"))
      files.push_back(entry.path());
  }
  const fs::path checkpoints = dir / "checkpoints";
  if (fs::is_directory(checkpoints, status))
    for (const auto& entry : fs::directory_iterator(checkpoints, status)) {
      const std::string f = entry.path().filename().string();
      if (f.rfind(name + "_step", 0) == 0 && entry.path().extension() == ".ckpt")
        files.push_back(entry.path());
    }
  std::sort(files.begin(), files.end());
  return files;
}

// Before a run writes anything: creates the directory, checks that files can be written in
// it, and refuses to mix this run's output with an earlier run's unless `overwrite` (which
// removes the earlier run's files) or `restart` (which continues them).
inline void prepareOutputDirectory(const std::filesystem::path& dir, const std::string& name,
                                   bool overwrite, bool restart) {
  namespace fs = std::filesystem;
  std::error_code error;
  fs::create_directories(dir, error);
  if (error || !fs::is_directory(dir))
    throw OutputDirectoryError("cannot create the output directory " + dir.string() + ": " +
                               (error ? error.message() : "a file of that name is in the way") +
                               " ([output] directory)");
  const fs::path probe = dir / (".tlsph-write-test-" + std::to_string(long(::getpid())));
  {
    std::ofstream test(probe);
    test << "test";
    test.close();
    const bool ok = static_cast<bool>(test);
    fs::remove(probe, error);
    if (!ok)
      throw OutputDirectoryError("cannot write files in the output directory " + dir.string() +
                                 " (no permission? read-only file system?)");
  }
  if (restart) return;
  const auto earlier = runOutputFiles(dir, name);
  if (earlier.empty()) return;
  if (!overwrite)
    throw OutputDirectoryError(
        "the output directory " + dir.string() + " already holds the output of a run (" +
        earlier.front().filename().string() + (earlier.size() > 1 ? ", ..." : "") +
        "): pass --overwrite to replace it, --restart=latest to continue that run, or set "
        "another [output] directory");
  for (const auto& f : earlier)
    fs::remove_all(f, error);  // a distributed frame's pieces are a directory
}

// Refuses a run whose planned output does not fit the free space of its file system.
inline void checkFreeSpace(const std::filesystem::path& dir, const OutputEstimate& e) {
  std::error_code error;
  const auto space = std::filesystem::space(dir, error);
  if (error) return;  // no answer (an unusual file system): the writes themselves will tell
  if (e.total() > double(space.available))
    throw OutputDirectoryError(
        "the run plans to write about " + byteText(e.total()) + " (" + std::to_string(e.frames) +
        " frames of " + byteText(e.frameBytes) + " uncompressed, series " +
        byteText(e.seriesBytes) + ", checkpoints " +
        byteText(e.checkpointBytes * double(e.checkpointsKept + 1)) + ") and " + dir.string() +
        " has " + byteText(double(space.available)) +
        " free: write fewer frames ([output] every_time, every_steps or fields = none), or "
        "point [output] directory to a larger file system");
}

}  // namespace tlsph
