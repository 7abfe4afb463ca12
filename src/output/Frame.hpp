// One output instant: particle positions plus named per-particle arrays, independent of any
// file format so the solver side never sees VTK.
#pragma once

#include <array>
#include <cstdint>
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
};

}  // namespace tlsph
