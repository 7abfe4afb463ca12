// A tlsph output frame (.vtu, or a distributed run's .pvtu of pieces) read back for comparison: the
// particles' reference positions X = x - u, which of them are ghosts, and the point fields as
// written.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <string_view>
#include <vector>

#include "output/Frame.hpp"

namespace tlsph {

struct ParticleFrame {
  std::filesystem::path file;
  double time = std::numeric_limits<double>::quiet_NaN();  // field data TIME, if present
  long step = -1;                                          // field data STEP, if present
  std::vector<std::array<double, 3>> reference;            // X = x - u, one per particle
  std::vector<std::uint8_t> ghost;  // 1 for clamp ghosts; all 0 without the flag
  bool hasGhostFlags = false;       // the frame carries the `ghost` flags
  std::vector<PointField> fields;   // every point array, as doubles

  std::size_t size() const { return reference.size(); }
  // nullptr if the frame has no point array of that name.
  const PointField* field(std::string_view name) const;
};

// Reads a frame written by `tlsph run` (any VTK XML unstructured grid, .vtu or .pvtu, with a
// 3-component point array `displacement`; a .pvtu's pieces in piece order). Throws
// std::runtime_error naming the file and, for a missing or malformed displacement, what to add to
// the scene's [output] fields.
ParticleFrame readParticleFrame(const std::filesystem::path& file);

}  // namespace tlsph
