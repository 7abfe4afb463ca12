// A named surface of a body (a gmsh physical group): the particles on it and the share of its
// area each carries, so that loads integrate over the true surface.
#pragma once

#include <array>
#include <vector>

#include "model/Types.hpp"

namespace tlsph {

template <int D>
struct SurfacePatch {
  std::vector<Index> particles;    // sorted
  std::vector<double> area;        // per particle: A_I = int_S lambda_I dA (sum: the area)
  std::vector<Vec<D>> areaVector;  // per particle: a_I = int_S lambda_I n dA, n outward
  std::vector<std::array<Index, D>> facets;  // linear facets (particle indices), normal outward
  double measure = 0.0;                      // the surface's area (2D: length per unit thickness)
};

}  // namespace tlsph
