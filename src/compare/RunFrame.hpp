// Which VTU frame of a tlsph run to compare: RUN is an output directory, a .pvd series or a
// single frame (.vtu, or .pvtu for a distributed run's frame in pieces).
#pragma once

#include <cstddef>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "output/PvdFile.hpp"

namespace tlsph {

struct FrameChoice {
  std::filesystem::path file;    // the frame's .vtu (or .pvtu)
  std::filesystem::path series;  // the .pvd it was chosen from; empty for a lone .vtu
  std::size_t index = 0;         // its position in the series (0-based)
  std::size_t count = 1;         // frames in the series
  double time = std::numeric_limits<double>::quiet_NaN();  // as listed in the .pvd
};

// run: a directory written by `tlsph run` (its summary.json names the .pvd; without one, the
// directory's only .pvd), a .pvd file, or a .vtu or .pvtu file. frame: "" or "last" for the last
// frame of the series, or a frame number N >= 0 (the position in the .pvd, which is the NNNNNN of
// NAME_NNNNNN.vtu); a lone .vtu takes no frame number. Throws std::runtime_error naming the
// path and what was expected.
FrameChoice chooseFrame(const std::filesystem::path& run, const std::string& frame);

// The entries of a .pvd collection in file order, `file` as written (relative to the .pvd's
// directory unless absolute). Throws std::runtime_error naming the file if it cannot be read or
// is not a VTK Collection.
std::vector<PvdEntry> readPvdFile(const std::filesystem::path& pvd);

// The path's extension in lower case, with its dot ("" without one).
std::string lowerExtension(const std::filesystem::path& path);

}  // namespace tlsph
