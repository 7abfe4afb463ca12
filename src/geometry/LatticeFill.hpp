// Particles for a body: the cell-centred lattice points inside a union of shapes.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "geometry/LatticeGrid.hpp"
#include "geometry/MessageText.hpp"
#include "geometry/PointSets.hpp"  // select() and boundingBox() go with filling
#include "geometry/Shape.hpp"
#include "model/Types.hpp"

namespace tlsph {

namespace geometry_detail {

// Inclusive lattice index ranges per axis; empty when lo > hi on some axis.
template <int D>
struct IndexRange {
  std::array<LatticeIndex, D> lo, hi;
};

// Where cell n is tested against the shapes: origin + (n + 1/2) dx evaluated in double, as the
// fill always did. The point is then placed at cell n of the binary grid (LatticeGrid.hpp), which
// is within (|n| + 2) q of it, so the exact coordinates change no scene's set of particles: a
// point that lies on a shape's face up to rounding (Cook's membrane's top edge passes through
// cell centres) keeps the decision it always had.
inline double testedCoordinate(double origin, LatticeIndex n, double dx) {
  return origin + (static_cast<double>(n) + 0.5) * dx;
}

// The indices n with lower <= testedCoordinate(n) <= upper, for lower and upper within the
// lattice's reach (|n| well below 2^51, so n + 1/2 is exact).
inline std::pair<LatticeIndex, LatticeIndex> indexSpan(double lower, double upper, double origin,
                                                       double dx) {
  auto lo = static_cast<LatticeIndex>(std::ceil((lower - origin) / dx - 0.5));
  auto hi = static_cast<LatticeIndex>(std::floor((upper - origin) / dx - 0.5));
  // The division rounds; settle the ends on the coordinates actually tested (monotone in n,
  // and off by at most one step).
  auto at = [&](LatticeIndex n) { return testedCoordinate(origin, n, dx); };
  for (int k = 0; k < 2 && at(lo - 1) >= lower; ++k)
    --lo;
  for (int k = 0; k < 2 && at(lo) < lower; ++k)
    ++lo;
  for (int k = 0; k < 2 && at(hi + 1) <= upper; ++k)
    ++hi;
  for (int k = 0; k < 2 && at(hi) > upper; ++k)
    --hi;
  return std::pair{lo, hi};
}

// Splits `axis` at the ends of the active ranges and calls visit(lo, hi, covering) for each slab
// [lo, hi] in increasing order that at least one range covers, with the covering ranges.
template <int D, class Visit>
void forEachSlab(const std::vector<IndexRange<D>>& ranges, int axis,
                 const std::vector<std::size_t>& active, Visit&& visit) {
  std::vector<LatticeIndex> cuts;
  for (std::size_t i : active) {
    cuts.push_back(ranges[i].lo[axis]);
    cuts.push_back(ranges[i].hi[axis] + 1);
  }
  std::sort(cuts.begin(), cuts.end());
  cuts.erase(std::unique(cuts.begin(), cuts.end()), cuts.end());
  std::vector<std::size_t> covering;
  for (std::size_t k = 0; k + 1 < cuts.size(); ++k) {
    const LatticeIndex lo = cuts[k], hi = cuts[k + 1] - 1;
    covering.clear();
    for (std::size_t i : active)
      if (ranges[i].lo[axis] <= lo && hi <= ranges[i].hi[axis]) covering.push_back(i);
    if (!covering.empty()) visit(lo, hi, covering);
  }
}

// Lattice points in the union of the active ranges, each counted once (double: it is compared
// with a limit, and may be astronomically large for a mistyped dx).
template <int D>
double unionCount(const std::vector<IndexRange<D>>& ranges, int axis,
                  const std::vector<std::size_t>& active) {
  double total = 0.0;
  forEachSlab<D>(ranges, axis, active,
                 [&](LatticeIndex lo, LatticeIndex hi, const std::vector<std::size_t>& covering) {
                   const auto width = static_cast<double>(hi - lo + 1);
                   total += axis == 0 ? width : width * unionCount<D>(ranges, axis - 1, covering);
                 });
  return total;
}

// Appends the points of the union inside a shape, walking the slabs from the last axis down so
// that x varies fastest; a point is tested only against the shapes whose range holds it, at its
// tested coordinates, and placed on the grid of `axes`.
template <int D>
void appendUnion(const std::vector<Shape<D>>& shapes, const std::vector<IndexRange<D>>& ranges,
                 int axis, const std::vector<std::size_t>& active,
                 const std::array<LatticeAxis, D>& axes, const Vec<D>& origin, double dx,
                 std::array<LatticeIndex, D>& n, std::vector<Vec<D>>& points) {
  forEachSlab<D>(ranges, axis, active,
                 [&](LatticeIndex lo, LatticeIndex hi, const std::vector<std::size_t>& covering) {
                   for (LatticeIndex m = lo; m <= hi; ++m) {
                     n[axis] = m;
                     if (axis > 0) {
                       appendUnion<D>(shapes, ranges, axis - 1, covering, axes, origin, dx, n,
                                      points);
                       continue;
                     }
                     Vec<D> tested;
                     for (int a = 0; a < D; ++a)
                       tested[a] = testedCoordinate(origin[a], n[a], dx);
                     if (std::any_of(covering.begin(), covering.end(),
                                     [&](std::size_t i) { return contains(shapes[i], tested); })) {
                       Vec<D> x;
                       for (int a = 0; a < D; ++a)
                         x[a] = axes[a].coordinate(n[a]);
                       points.push_back(x);
                     }
                   }
                 });
}

inline std::string countText(double count) {
  return count < 0x1p53 ? std::to_string(static_cast<std::uint64_t>(count)) : numberText(count);
}

}  // namespace geometry_detail

// The axes of the lattice of spacing dx and origin `origin` on which fillLattice places the
// points of `shapes` (LatticeGrid.hpp: coordinates exact on one binary grid, its reach that of
// all the shapes' bounding boxes and the origin, so that every body of a scene shares it).
// Throws std::invalid_argument if dx <= 0, if shapes is empty or one is invalid or unbounded
// (half-space), or if a shape or the origin lies more than kMaxLatticeSpacings spacings from
// zero.
template <int D>
std::array<LatticeAxis, D> latticeAxes(const std::vector<Shape<D>>& shapes, double dx,
                                       const Vec<D>& origin = Vec<D>::Zero()) {
  using namespace geometry_detail;
  if (!(dx > 0.0) || !std::isfinite(dx))
    throw std::invalid_argument(
        "fillLattice: lattice spacing dx must be positive and finite, got " + numberText(dx));
  if (!latticeSpacingUsable(dx))
    throw std::invalid_argument("fillLattice: lattice spacing dx " + numberText(dx) +
                                " is outside [2^-960, 2^960]");
  if (!origin.allFinite())
    throw std::invalid_argument("fillLattice: lattice origin must be finite, got " +
                                pointText<D>(origin));
  if (shapes.empty()) throw std::invalid_argument("fillLattice: no shapes to fill");
  auto tooFar = [&](const std::string& what, int a) {
    return std::invalid_argument(what + " reaches more than 2^20 lattice spacings (dx " +
                                 numberText(dx) + ") from zero along " + std::string(axisName(a)));
  };
  double largest = origin.cwiseAbs().maxCoeff();
  for (int a = 0; a < D; ++a)
    if (!withinLatticeReach(std::abs(origin[a]), dx)) throw tooFar("fillLattice: the origin", a);
  for (std::size_t i = 0; i < shapes.size(); ++i) {
    const std::string which = "fillLattice: shape " + std::to_string(i);
    try {
      validate(shapes[i]);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(which + " is invalid: " + e.what());
    }
    const auto box = bounds(shapes[i]);
    if (!box)
      throw std::invalid_argument(which + " (" + std::string(shapeName(shapes[i])) +
                                  ") is unbounded and cannot be filled with particles; it can "
                                  "only select particles of a region");
    for (int a = 0; a < D; ++a) {
      const double far = std::max(std::abs(box->min()[a]), std::abs(box->max()[a]));
      if (!withinLatticeReach(far, dx)) throw tooFar(which, a);
      largest = std::max(largest, far);
    }
  }
  std::array<LatticeAxis, D> axes;
  for (int a = 0; a < D; ++a)
    axes[a] = *latticeAxis(origin[a], dx, latticeReach(largest, dx));
  return axes;
}

// The point at which the fill tested the lattice point X that it placed on `axes` (the lattice
// of spacing dx and origin `origin`): what else decides about a lattice point (holes, the body it
// belongs to) decides there too, so that the exact grid changes no particle's assignment.
template <int D>
Vec<D> testedPoint(const std::array<LatticeAxis, D>& axes, const Vec<D>& X, double dx,
                   const Vec<D>& origin = Vec<D>::Zero()) {
  Vec<D> tested;
  for (int a = 0; a < D; ++a)
    tested[a] = geometry_detail::testedCoordinate(origin[a], axes[a].index(X[a]), dx);
  return tested;
}

// Cell-centred lattice points origin + (n + 1/2) dx (n integer, any sign; placed on the grid of
// latticeAxes, exactly) that lie inside at least one of `shapes` (a union), each point once,
// ordered x fastest, then y, then z. Whether a point lies inside is decided at
// testedCoordinate(): origin + (n + 1/2) dx as evaluated in double. Throws what latticeAxes
// throws, and std::length_error if the union of the shapes' bounding boxes holds more than
// maxPoints lattice points: a memory guard checked before any point is made.
template <int D>
std::vector<Vec<D>> fillLattice(const std::vector<Shape<D>>& shapes, double dx,
                                const Vec<D>& origin = Vec<D>::Zero(),
                                std::size_t maxPoints = 50'000'000) {
  using namespace geometry_detail;
  const std::array<LatticeAxis, D> axes = latticeAxes<D>(shapes, dx, origin);
  std::vector<IndexRange<D>> ranges(shapes.size());
  std::vector<std::size_t> active;  // shapes whose bounds hold at least one lattice point
  for (std::size_t i = 0; i < shapes.size(); ++i) {
    const auto box = bounds(shapes[i]);
    bool empty = false;
    for (int a = 0; a < D; ++a) {
      const auto span = indexSpan(box->min()[a], box->max()[a], origin[a], dx);
      ranges[i].lo[a] = span.first;
      ranges[i].hi[a] = span.second;
      empty = empty || span.first > span.second;
    }
    if (!empty) active.push_back(i);
  }

  const double count = unionCount<D>(ranges, D - 1, active);
  if (count > static_cast<double>(maxPoints))
    throw std::length_error("fillLattice: the shapes' bounding boxes hold " + countText(count) +
                            " lattice points at dx " + numberText(dx) + ", more than the limit " +
                            std::to_string(maxPoints) + " (maxPoints)");

  std::vector<Vec<D>> points;
  std::array<LatticeIndex, D> n{};
  appendUnion<D>(shapes, ranges, D - 1, active, axes, origin, dx, n, points);
  return points;
}

}  // namespace tlsph
