// Primitive shapes that bodies and regions are built from. Every shape is closed (its boundary
// belongs to it) and contains() is exact, without tolerance: lattice particles sit at cell
// centres, so shapes aligned with cell faces never have a particle on their boundary.
#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "geometry/MessageText.hpp"
#include "geometry/PolygonOps.hpp"
#include "model/Types.hpp"

namespace tlsph {

template <int D>
using BoundingBox = Eigen::AlignedBox<double, D>;

// Axis-aligned box lower <= x <= upper.
template <int D>
struct Box {
  static_assert(D == 2 || D == 3);
  static constexpr std::string_view name = "box";
  Vec<D> lower = Vec<D>::Zero();
  Vec<D> upper = Vec<D>::Zero();

  bool contains(const Vec<D>& x) const {
    return (x.array() >= lower.array()).all() && (x.array() <= upper.array()).all();
  }
  BoundingBox<D> bounds() const { return BoundingBox<D>(lower, upper); }
};

// 3D: the finite cylinder of `radius` around the segment start -> end. 2D: the disc of `radius`
// around start (end is ignored), so that one scene description serves both dimensions.
template <int D>
struct Cylinder {
  static_assert(D == 2 || D == 3);
  static constexpr std::string_view name = "cylinder";
  Vec<D> start = Vec<D>::Zero();
  Vec<D> end = Vec<D>::Zero();
  double radius = 0.0;

  bool contains(const Vec<D>& x) const {
    const Vec<D> d = x - start;
    if constexpr (D == 2) {
      return d.squaredNorm() <= radius * radius;
    } else {
      const Vec<D> a = end - start;
      const double s = d.dot(a), aa = a.squaredNorm();
      if (s < 0.0 || s > aa) return false;
      return (d - (s / aa) * a).squaredNorm() <= radius * radius;
    }
  }

  BoundingBox<D> bounds() const {
    if constexpr (D == 2) {
      return BoundingBox<D>(start.array() - radius, start.array() + radius);
    } else {
      // The end discs reach radius * sin(angle between the axis and coordinate axis i) along i.
      const Vec<D> a = end - start;
      const double aa = a.squaredNorm();
      Vec<D> reach;
      for (int i = 0; i < D; ++i)
        reach[i] = radius * std::sqrt(std::max(0.0, 1.0 - a[i] * a[i] / aa));
      return BoundingBox<D>(start.cwiseMin(end) - reach, start.cwiseMax(end) + reach);
    }
  }
};

// A simple polygon (either orientation, possibly non-convex). 2D: its area. 3D: the prism that
// extrudes it along coordinate `axis` from `from` to `to`; vertex coordinates are the two other
// axes in increasing order (axis 2 -> (x, y), axis 1 -> (x, z), axis 0 -> (y, z)).
template <int D>
struct Polygon {
  static_assert(D == 2 || D == 3);
  static constexpr std::string_view name = "polygon";
  std::vector<Vec<2>> vertices;
  int axis = 2;       // 3D only
  double from = 0.0;  // 3D only
  double to = 0.0;    // 3D only

  // The coordinate axes of the polygon's plane.
  std::array<int, 2> planeAxes() const {
    if constexpr (D == 2)
      return {0, 1};
    else
      return {axis == 0 ? 1 : 0, axis == 2 ? 1 : 2};
  }

  bool contains(const Vec<D>& x) const {
    if constexpr (D == 3)
      if (x[axis] < from || x[axis] > to) return false;
    const auto [u, v] = planeAxes();
    return polygon::contains(vertices, Vec<2>(x[u], x[v]));
  }

  BoundingBox<D> bounds() const {
    BoundingBox<2> planar;
    for (const Vec<2>& p : vertices)
      planar.extend(p);
    const auto [u, v] = planeAxes();
    Vec<D> lower, upper;
    lower[u] = planar.min().x(), lower[v] = planar.min().y();
    upper[u] = planar.max().x(), upper[v] = planar.max().y();
    if constexpr (D == 3) lower[axis] = from, upper[axis] = to;
    return BoundingBox<D>(lower, upper);
  }
};

// The closed half-space on the side `normal` points to: (x - point) . normal >= 0. Unbounded,
// so it can select particles of a region but cannot be filled with particles.
template <int D>
struct HalfSpace {
  static_assert(D == 2 || D == 3);
  static constexpr std::string_view name = "half-space";
  Vec<D> point = Vec<D>::Zero();
  Vec<D> normal = Vec<D>::Zero();  // need not be unit

  bool contains(const Vec<D>& x) const { return (x - point).dot(normal) >= 0.0; }
};

// Disc (2D) or sphere (3D).
template <int D>
struct Ball {
  static_assert(D == 2 || D == 3);
  static constexpr std::string_view name = "ball";
  Vec<D> centre = Vec<D>::Zero();
  double radius = 0.0;

  bool contains(const Vec<D>& x) const { return (x - centre).squaredNorm() <= radius * radius; }
  BoundingBox<D> bounds() const {
    return BoundingBox<D>(centre.array() - radius, centre.array() + radius);
  }
};

template <int D>
using Shape = std::variant<Box<D>, Cylinder<D>, Polygon<D>, HalfSpace<D>, Ball<D>>;

template <int D>
bool contains(const Shape<D>& shape, const Vec<D>& x) {
  return std::visit([&x](const auto& s) { return s.contains(x); }, shape);
}

// The axis-aligned bounds, or nullopt for an unbounded shape (half-space).
template <int D>
std::optional<BoundingBox<D>> bounds(const Shape<D>& shape) {
  return std::visit(
      [](const auto& s) -> std::optional<BoundingBox<D>> {
        if constexpr (requires { s.bounds(); })
          return s.bounds();
        else
          return std::nullopt;
      },
      shape);
}

template <int D>
std::string_view shapeName(const Shape<D>& shape) {
  return std::visit([](const auto& s) { return s.name; }, shape);
}

// Validation: std::invalid_argument, naming the shape and the problem, for degenerate input.

namespace geometry_detail {

[[noreturn]] inline void reject(std::string_view shape, const std::string& problem) {
  throw std::invalid_argument(std::string(shape) + ": " + problem);
}

inline void requirePositiveRadius(std::string_view shape, double radius) {
  if (!(radius > 0.0) || !std::isfinite(radius))
    reject(shape, "radius must be positive and finite, got " + numberText(radius));
}

}  // namespace geometry_detail

template <int D>
void validate(const Box<D>& box) {
  using namespace geometry_detail;
  if (!box.lower.allFinite() || !box.upper.allFinite())
    reject(box.name, "corners must be finite, got lower " + pointText<D>(box.lower) + ", upper " +
                         pointText<D>(box.upper));
  for (int a = 0; a < D; ++a)
    if (!(box.upper[a] > box.lower[a]))
      reject(box.name, "upper <= lower on axis " + std::string(axisName(a)) + " (lower " +
                           numberText(box.lower[a]) + ", upper " + numberText(box.upper[a]) + ")");
}

template <int D>
void validate(const Cylinder<D>& cylinder) {
  using namespace geometry_detail;
  requirePositiveRadius(cylinder.name, cylinder.radius);
  if (!cylinder.start.allFinite())
    reject(cylinder.name, "start must be finite, got " + pointText<D>(cylinder.start));
  if constexpr (D == 3) {
    if (!cylinder.end.allFinite())
      reject(cylinder.name, "end must be finite, got " + pointText<D>(cylinder.end));
    if (cylinder.start == cylinder.end)
      reject(cylinder.name, "start and end coincide at " + pointText<D>(cylinder.start) +
                                ", the axis has no length");
  }
}

template <int D>
void validate(const Polygon<D>& poly) {
  using namespace geometry_detail;
  const auto& v = poly.vertices;
  if (v.size() < 3) reject(poly.name, "needs at least 3 vertices, got " + std::to_string(v.size()));
  for (std::size_t i = 0; i < v.size(); ++i)
    if (!v[i].allFinite())
      reject(poly.name, "vertex " + std::to_string(i) + " is not finite: " + pointText<2>(v[i]));
  if constexpr (D == 3) {
    if (poly.axis < 0 || poly.axis > 2)
      reject(poly.name, "extrusion axis must be 0, 1 or 2, got " + std::to_string(poly.axis));
    if (!std::isfinite(poly.from) || !std::isfinite(poly.to) || !(poly.from < poly.to))
      reject(poly.name, "extrusion needs from < to along " + std::string(axisName(poly.axis)) +
                            ", got from " + numberText(poly.from) + ", to " + numberText(poly.to));
  }
  for (std::size_t i = 0; i < v.size(); ++i)
    if (v[i] == v[(i + 1) % v.size()])
      reject(poly.name, "vertices " + std::to_string(i) + " and " +
                            std::to_string((i + 1) % v.size()) + " coincide at " +
                            pointText<2>(v[i]));
  // Checked before simplicity: a line folds back on itself, and this is the clearer message.
  if (polygon::collinear(v)) reject(poly.name, "zero area: all vertices lie on one line");
  if (const auto edges = polygon::selfIntersection(v))
    reject(poly.name, "edges " + std::to_string(edges->first) + " and " +
                          std::to_string(edges->second) +
                          " intersect; the polygon must be simple (edge i runs from vertex i to "
                          "vertex i + 1)");
}

template <int D>
void validate(const HalfSpace<D>& half) {
  using namespace geometry_detail;
  if (!half.point.allFinite() || !half.normal.allFinite())
    reject(half.name, "point and normal must be finite, got point " + pointText<D>(half.point) +
                          ", normal " + pointText<D>(half.normal));
  if (half.normal.isZero(0.0)) reject(half.name, "normal is zero");
}

template <int D>
void validate(const Ball<D>& ball) {
  using namespace geometry_detail;
  requirePositiveRadius(ball.name, ball.radius);
  if (!ball.centre.allFinite())
    reject(ball.name, "centre must be finite, got " + pointText<D>(ball.centre));
}

template <int D>
void validate(const Shape<D>& shape) {
  std::visit([](const auto& s) { validate(s); }, shape);
}

}  // namespace tlsph
