// The pair loops' gathered values with their 3-vectors padded to 4 doubles (issue 12).
// A column of a padded 3 x C matrix is one 256-bit register, so S_J t_IJ, R_J T_IJ, F_J X_IJ
// and w_IJ X_IJ^T are one vector multiply-add per column instead of a 2-wide and a scalar one
// (Zen 4, defaults, 5,312 particles: 20 % fewer cycles per step). The fourth row is zero and
// stays zero: only the top D rows are ever written (topRows()). In 2D nothing is padded: a
// padded type is the plain one.
#pragma once

#include <Eigen/Core>

#include "tlsph/Types.hpp"

namespace tlsph {

template <int D>
constexpr int kPaddedRows = D == 3 ? 4 : D;

template <int D, int C = D>
using PaddedMat = Eigen::Matrix<double, kPaddedRows<D>, C>;

template <int D>
using PaddedVec = PaddedMat<D, 1>;

// m with a zero fourth row (3D), m itself (2D); C = 1 for a vector.
template <int D, int C>
PaddedMat<D, C> padded(const Eigen::Matrix<double, D, C>& m) {
  PaddedMat<D, C> p = PaddedMat<D, C>::Zero();
  p.template topRows<D>() = m;
  return p;
}

}  // namespace tlsph
