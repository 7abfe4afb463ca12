// Queries on point sets: which points a region selects, and the box they span.
#pragma once

#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "geometry/Shape.hpp"
#include "model/Types.hpp"

namespace tlsph {

// Indices (ascending) of the points inside `region`; the region is validated first, so that a
// degenerate region (e.g. a zero normal) is an error rather than a silent everything-or-nothing.
template <int D>
std::vector<Index> select(const Shape<D>& region, const std::vector<Vec<D>>& points) {
  validate(region);
  if (points.size() > static_cast<std::size_t>(std::numeric_limits<Index>::max()))
    throw std::length_error("select: " + std::to_string(points.size()) +
                            " points exceed the range of tlsph::Index");
  std::vector<Index> inside;
  for (std::size_t i = 0; i < points.size(); ++i)
    if (contains(region, points[i])) inside.push_back(static_cast<Index>(i));
  return inside;
}

// The smallest axis-aligned box holding all points; empty (isEmpty()) for no points.
template <int D>
BoundingBox<D> boundingBox(const std::vector<Vec<D>>& points) {
  BoundingBox<D> box;
  for (const Vec<D>& x : points)
    box.extend(x);
  return box;
}

}  // namespace tlsph
