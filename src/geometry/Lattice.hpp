// Regular particle lattices: particle i sits at the centre of lattice cell i.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "geometry/LatticeGrid.hpp"
#include "model/Types.hpp"

namespace tlsph {

// Positions lower + (n + 1/2) dx for n in [0, counts) per axis, x fastest, exact on the binary
// grid of LatticeGrid.hpp (reach: the block's own extent), so that equal offsets between
// particles are bitwise equal. Throws std::invalid_argument if dx is not positive and finite or
// the block reaches more than kMaxLatticeSpacings spacings from zero.
template <int D>
std::vector<Vec<D>> cellCentredLattice(const Vec<D>& lower, const std::array<int, D>& counts,
                                       double dx) {
  double largest = 0.0;
  for (int a = 0; a < D; ++a)
    largest = std::max({largest, std::abs(lower[a]), std::abs(lower[a] + counts[a] * dx)});
  std::array<LatticeAxis, D> axes;
  for (int a = 0; a < D; ++a) {
    const auto axis = latticeAxis(lower[a], dx, latticeReach(largest, dx));
    if (!axis)
      throw std::invalid_argument("cellCentredLattice: a block of spacing " + std::to_string(dx) +
                                  " reaching " + std::to_string(largest) +
                                  " from zero (at most 2^20 spacings)");
    axes[a] = *axis;
  }
  std::size_t total = 1;
  for (int c : counts)
    total *= static_cast<std::size_t>(c);
  std::vector<Vec<D>> points;
  points.reserve(total);
  std::array<int, D> n{};
  for (std::size_t p = 0; p < total; ++p) {
    Vec<D> x;
    for (int a = 0; a < D; ++a)
      x[a] = axes[a].coordinate(n[a]);
    points.push_back(x);
    for (int a = 0; a < D && ++n[a] == counts[a]; ++a)
      n[a] = 0;
  }
  return points;
}

}  // namespace tlsph
