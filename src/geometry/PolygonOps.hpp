// Planar polygon predicates: area, point-in-polygon and simplicity. Vertices are given in order
// (either orientation), the closing edge runs from the last vertex back to the first.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <optional>
#include <utility>
#include <vector>

#include "model/Types.hpp"

namespace tlsph::polygon {

// Twice the signed area of triangle (a, b, c): > 0 when c lies left of a -> b.
inline double orientation(const Vec<2>& a, const Vec<2>& b, const Vec<2>& c) {
  return (b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x());
}

// Whether p lies in the axis-aligned box spanned by a and b (used once p is known collinear).
inline bool inSpan(const Vec<2>& a, const Vec<2>& b, const Vec<2>& p) {
  return std::min(a.x(), b.x()) <= p.x() && p.x() <= std::max(a.x(), b.x()) &&
         std::min(a.y(), b.y()) <= p.y() && p.y() <= std::max(a.y(), b.y());
}

inline bool onSegment(const Vec<2>& a, const Vec<2>& b, const Vec<2>& p) {
  return orientation(a, b, p) == 0.0 && inSpan(a, b, p);
}

// Closed segments [p1, p2] and [q1, q2] share at least one point.
inline bool segmentsIntersect(const Vec<2>& p1, const Vec<2>& p2, const Vec<2>& q1,
                              const Vec<2>& q2) {
  const double d1 = orientation(q1, q2, p1), d2 = orientation(q1, q2, p2);
  const double d3 = orientation(p1, p2, q1), d4 = orientation(p1, p2, q2);
  if (((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0)))
    return true;
  return (d1 == 0 && inSpan(q1, q2, p1)) || (d2 == 0 && inSpan(q1, q2, p2)) ||
         (d3 == 0 && inSpan(p1, p2, q1)) || (d4 == 0 && inSpan(p1, p2, q2));
}

// Shoelace formula; positive for counter-clockwise vertices.
inline double signedArea(const std::vector<Vec<2>>& v) {
  double twice = 0.0;
  for (std::size_t i = 0, j = v.size() - 1; i < v.size(); j = i++)
    twice += v[j].x() * v[i].y() - v[i].x() * v[j].y();
  return 0.5 * twice;
}

// All vertices on one line, up to rounding relative to the polygon's extent (vertices computed
// along a slanted line are rarely exactly collinear).
inline bool collinear(const std::vector<Vec<2>>& v) {
  std::size_t far = 0;
  for (std::size_t i = 1; i < v.size(); ++i)
    if ((v[i] - v[0]).squaredNorm() > (v[far] - v[0]).squaredNorm()) far = i;
  const double tolerance = 1e-12 * (v[far] - v[0]).squaredNorm();
  return std::all_of(v.begin(), v.end(), [&](const Vec<2>& p) {
    return std::abs(orientation(v[0], v[far], p)) <= tolerance;
  });
}

// Closed point-in-polygon test: points on an edge are inside (as for the other shapes);
// elsewhere the even-odd crossing number of a ray towards +x decides, which makes the answer
// independent of the orientation. Each edge counts for y in the half-open range between its
// end points, so a ray through a vertex is counted once.
inline bool contains(const std::vector<Vec<2>>& v, const Vec<2>& p) {
  bool inside = false;
  for (std::size_t i = 0, j = v.size() - 1; i < v.size(); j = i++) {
    const Vec<2>& a = v[j];
    const Vec<2>& b = v[i];
    const double o = orientation(a, b, p);
    if (o == 0.0 && inSpan(a, b, p)) return true;
    // The sign of o tells on which side of p the edge crosses p's horizontal line, without the
    // rounding of an explicit crossing abscissa.
    if ((a.y() > p.y()) != (b.y() > p.y()) && (b.y() > a.y() ? o > 0.0 : o < 0.0)) inside = !inside;
  }
  return inside;
}

// The first pair of edges (i < j; edge i runs from vertex i to i + 1) that meet other than at
// the vertex shared by neighbouring edges, or nullopt for a simple polygon.
inline std::optional<std::pair<std::size_t, std::size_t>> selfIntersection(
    const std::vector<Vec<2>>& v) {
  const std::size_t n = v.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Vec<2>& a = v[i];
    const Vec<2>& b = v[(i + 1) % n];
    for (std::size_t j = i + 1; j < n; ++j) {
      const Vec<2>& c = v[j];
      const Vec<2>& d = v[(j + 1) % n];
      if (j == i + 1 || (i == 0 && j == n - 1)) {
        // Neighbours share one vertex; they overlap only if they fold back along one line.
        const Vec<2>& shared = j == i + 1 ? b : a;
        const Vec<2>& p = j == i + 1 ? a : b;
        const Vec<2>& q = j == i + 1 ? d : c;
        if (orientation(p, shared, q) == 0.0 && (p - shared).dot(q - shared) > 0.0)
          return std::pair{i, j};
      } else if (segmentsIntersect(a, b, c, d)) {
        return std::pair{i, j};
      }
    }
  }
  return std::nullopt;
}

}  // namespace tlsph::polygon
