// The binary grid that holds a cell-centred lattice's coordinates exactly.
//
// Coordinates origin + (n + 1/2) dx evaluated in floating point round differently at each n, so
// two particles with the same neighbourhood see offsets X_J - X_I that differ in the last bits,
// and so do their rows of per-pair values (gradients, fits, separations): each particle's row is
// then distinct and the pair loops stream all of them. Here every coordinate of a lattice is an
// integer multiple of one power of two q: the spacing is an even number of steps
// (dx' = step q, within q of dx) and the origin a whole number, so the coordinate of cell n,
// (first + n step) q, is exact, every offset between two cells is exact, and particles with the
// same neighbourhood have bitwise the same rows. With the origin at zero the cells on either side
// stay mirror images bit for bit (step is even).
//
// q follows the largest coordinate the lattice holds (its reach): q = 2^(ilogb(reach) - 50), so
// every coordinate's integer stays below 2^51 and every difference is exact. A lattice reaches at
// most kMaxLatticeSpacings spacings from zero: then dx' is within 2^-30 of dx, and a cell n
// spacings from zero moves by at most (n + 2) q <= 2^-10 dx from origin + (n + 1/2) dx (a body
// of 1 m at dx = 0.01 m: at most 1.5e-14 m, test_geometry).
#pragma once

#include <cmath>
#include <cstdint>
#include <optional>

namespace tlsph {

using LatticeIndex = std::int64_t;

// The farthest a lattice may reach from zero, in spacings.
inline constexpr double kMaxLatticeSpacings = 0x1p20;

// The reach of a lattice of spacing dx whose points (and their neighbours' searches) lie within
// `largest` of zero along every axis: two spacings of margin for the searches around its ends.
inline double latticeReach(double largest, double dx) {
  return largest + 2.0 * dx;
}
// Whether a lattice of spacing dx (positive, finite, between 2^-960 and 2^960, so that its grid's
// step and its reach are normal numbers) may reach `largest` from zero.
inline bool latticeSpacingUsable(double dx) {
  return dx > 0.0 && std::isfinite(dx) && std::abs(std::ilogb(dx)) <= 960;
}
inline bool withinLatticeReach(double largest, double dx) {
  return latticeSpacingUsable(dx) && std::isfinite(largest) &&
         latticeReach(largest, dx) <= kMaxLatticeSpacings * dx;
}

// One axis of a lattice: cell n sits at (first + n step) quantum.
struct LatticeAxis {
  double quantum = 0.0;    // q, a power of two
  std::int64_t first = 0;  // cell 0's coordinate / q: the origin plus half a spacing
  std::int64_t step = 0;   // the spacing / q (even)

  double coordinate(LatticeIndex n) const {
    return static_cast<double>(first + n * step) * quantum;
  }
  double spacing() const { return static_cast<double>(step) * quantum; }
  // The cell nearest to coordinate x.
  LatticeIndex index(double x) const {
    return std::llround((x / quantum - static_cast<double>(first)) / static_cast<double>(step));
  }
  // Whether cell n's coordinate is exact (its integer below 2^53); the lattice's own cells are.
  bool holds(LatticeIndex n) const {
    constexpr std::int64_t limit = std::int64_t{1} << 53;
    const std::int64_t room = limit - (first < 0 ? -first : first);
    return room > 0 && (n < 0 ? -n : n) < room / step;
  }
};

// The axis with origin `origin` (rounded to the grid) for a lattice of spacing dx reaching
// `reach` >= |origin| from zero; nullopt if dx is not usable (latticeSpacingUsable) or the
// reach is more than kMaxLatticeSpacings spacings. Every axis of a lattice (and every body of a
// scene) must use the same reach, so that they share q and the spacing.
inline std::optional<LatticeAxis> latticeAxis(double origin, double dx, double reach) {
  if (!latticeSpacingUsable(dx) || !std::isfinite(origin) || !std::isfinite(reach) ||
      !(reach <= kMaxLatticeSpacings * dx) || !(std::abs(origin) <= reach))
    return std::nullopt;
  LatticeAxis axis;
  axis.quantum = std::ldexp(1.0, std::ilogb(reach) - 50);
  axis.step = 2 * std::llround(dx / (2.0 * axis.quantum));
  axis.first = std::llround(origin / axis.quantum) + axis.step / 2;
  return axis;
}

}  // namespace tlsph
