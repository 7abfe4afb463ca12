// The quadrature moments of each particle's share of the body, which the Taylor quadrature term
// (method/TaylorCorrection.hpp) corrects the one-point energy sum with. The particles' weights
// w_I form a partition of unity over the body (a lattice cell's indicator; a mesh node's hat
// function), V_I = int w_I dV, and
//   mu_I = 1/V_I int w_I (X - X_I) dV           the offset of the weight's centroid from X_I,
//   N_I  = 1/V_I int w_I (X - X_I)(X - X_I)^T dV  its second moment about X_I (symmetric).
// A particle at the centre of its lattice cell of side l_I = V_I^(1/d) has mu = 0 and
// N = l^2/12 1; a node of a mesh, whose hat leans into the body at a surface, has neither.
#pragma once

#include <cmath>
#include <span>

#include "model/Types.hpp"

namespace tlsph {

template <int D>
struct QuadratureMoments {
  std::span<const Vec<D>> offset;  // mu_I; empty: every particle the centre of its lattice cell
  std::span<const Mat<D>> spread;  // N_I; empty with offset

  bool lattice() const { return offset.empty(); }
};

// N of a lattice cell of volume V: l^2/12 1 with l = V^(1/d).
template <int D>
Mat<D> latticeSpread(double V) {
  const double l = std::pow(V, 1.0 / D);
  return (l * l / 12.0) * Mat<D>::Identity();
}

}  // namespace tlsph
