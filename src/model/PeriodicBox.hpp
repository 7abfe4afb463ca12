// Optional periodicity of the reference configuration, axis by axis.
#pragma once

#include <array>
#include <cmath>

#include "model/Types.hpp"

namespace tlsph {

template <int D>
struct PeriodicBox {
  std::array<bool, D> periodic{};  // all false: a free body
  Vec<D> origin = Vec<D>::Zero();
  Vec<D> length = Vec<D>::Zero();  // box edge along each periodic axis

  bool any() const {
    for (bool p : periodic)
      if (p) return true;
    return false;
  }

  // Minimum-image separation X_I - X_J.
  Vec<D> separation(const Vec<D>& Xi, const Vec<D>& Xj) const {
    Vec<D> d = Xi - Xj;
    for (int a = 0; a < D; ++a)
      if (periodic[a]) d[a] -= length[a] * std::round(d[a] / length[a]);
    return d;
  }
};

}  // namespace tlsph
