// One output instant: particle positions plus named per-particle arrays, independent of any
// file format so the solver side never sees VTK.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace tlsph {

struct PointField {
  std::string name;            // e.g. "displacement", "von_mises"
  int components = 1;          // 1 scalar, 3 vector, 9 tensor (row-major); 2D data zero-padded
  std::vector<double> values;  // components * pointCount, point-major
};

// Integer markers (ghost, group, ...) kept apart from doubles so they stay compact and exact.
struct PointFlags {
  std::string name;
  std::vector<std::uint8_t> values;  // one per point
};

struct Frame {
  double time = 0.0;
  long step = 0;
  std::vector<std::array<double, 3>> points;  // current positions (2D: z = 0)
  std::vector<PointField> fields;
  std::vector<PointFlags> flags;
  // Written as the Int64 point array `id` when present: each point's particle number in the
  // whole body, for a piece of a distributed run's frame (in a whole frame point k is
  // particle k). Present and empty for a piece without points, so every piece has the array.
  std::optional<std::vector<std::int64_t>> ids;
};

}  // namespace tlsph
