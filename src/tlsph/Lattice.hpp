// Regular particle lattices: particle i sits at the centre of lattice cell i.
#pragma once

#include <array>
#include <vector>

#include "tlsph/Types.hpp"

namespace tlsph {

// Positions lower + (n + 1/2) dx for n in [0, counts) per axis, x fastest.
template <int D>
std::vector<Vec<D>> cellCentredLattice(const Vec<D>& lower, const std::array<int, D>& counts,
                                       double dx) {
  std::size_t total = 1;
  for (int c : counts)
    total *= static_cast<std::size_t>(c);
  std::vector<Vec<D>> points;
  points.reserve(total);
  std::array<int, D> n{};
  for (std::size_t p = 0; p < total; ++p) {
    Vec<D> x;
    for (int a = 0; a < D; ++a)
      x[a] = lower[a] + (n[a] + 0.5) * dx;
    points.push_back(x);
    for (int a = 0; a < D && ++n[a] == counts[a]; ++a)
      n[a] = 0;
  }
  return points;
}

}  // namespace tlsph
