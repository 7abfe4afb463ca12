// The order in which a scene numbers its lattice points: the axis along which the
// points extend furthest varies slowest, the shortest fastest. A neighbour's index then lies
// within about H/dx cross-sections of the particle's own (a beam along x numbered with x
// fastest puts it H/dx whole x-y layers away), so the pair loops find the neighbours' values
// in the first cache levels, and two threads, each summing a contiguous range of particles,
// share few sources at the edge of their ranges. Measured on the benchmark beam: it pays on two
// threads and out of cache (docs/performance.md).
#pragma once

#include <algorithm>
#include <array>
#include <numeric>
#include <vector>

#include "model/Types.hpp"

namespace tlsph {

// The axes from slowest to fastest: by decreasing extent of the points' bounding box, equal
// extents keeping the lattice fill's order (the last axis slowest), so that a cube keeps it.
template <int D>
std::array<int, D> localityAxes(const std::vector<Vec<D>>& points) {
  Vec<D> lower = Vec<D>::Constant(0.0), upper = Vec<D>::Constant(0.0);
  if (!points.empty()) {
    lower = upper = points.front();
    for (const auto& X : points) {
      lower = lower.cwiseMin(X);
      upper = upper.cwiseMax(X);
    }
  }
  const Vec<D> extent = upper - lower;
  std::array<int, D> axes;
  std::iota(axes.begin(), axes.end(), 0);
  std::reverse(axes.begin(), axes.end());  // the fill's order: last axis slowest
  std::stable_sort(axes.begin(), axes.end(), [&](int a, int b) { return extent[a] > extent[b]; });
  return axes;
}

// Sorts points (distinct lattice points, or any distinct points) lexicographically by their
// coordinates along localityAxes(points): the coordinates are compared exactly, so the order
// does not depend on the order the points came in.
template <int D>
void sortForLocality(std::vector<Vec<D>>& points) {
  const auto axes = localityAxes<D>(points);
  std::sort(points.begin(), points.end(), [&](const Vec<D>& p, const Vec<D>& q) {
    for (int a : axes)
      if (p[a] != q[a]) return p[a] < q[a];
    return false;
  });
}

// The lattice fill's own order (the last axis slowest, x fastest), compared exactly: where a
// choice must depend on the particles' places and not on how LocalityOrder numbered them (a
// random field's draw order, a nearest probe's tie).
template <int D>
bool latticeOrderBefore(const Vec<D>& p, const Vec<D>& q) {
  for (int a = D - 1; a >= 0; --a)
    if (p[a] != q[a]) return p[a] < q[a];
  return false;
}

}  // namespace tlsph
