// The textbook hourglass force (6.80)-(6.81) (Ganzenmueller 2015), kept selectable
// ([hourglass] form = ganzenmueller) to reproduce the chapter:
//   eps_IJ = [x_IJ - 1/2 (F_I + F_J) X_IJ] . x_IJ/|x_IJ|
//   f_I = -V_I sum_J c_IJ eps_IJ x_IJ/|x_IJ|
// A central, antisymmetric pair force (momentum and angular momentum conserved, zero for
// affine fields), but not the gradient of an energy: the solver books its work.
#pragma once

#include <vector>

#include "model/Types.hpp"

namespace tlsph {

template <int D>
class GanzenmuellerHourglass {
 public:
  explicit GanzenmuellerHourglass(PairArray<double> pairCoefficient)
      : c_(std::move(pairCoefficient)) {}

  // The pair's contribution to f_I / V_I; F the linear-corrected deformation gradients.
  Vec<D> pair(Index k, const Vec<D>& Xij, const Vec<D>& xij, const Mat<D>& Fi,
              const Mat<D>& Fj) const {
    const Vec<D> error = xij - 0.5 * ((Fi + Fj) * Xij);          // (6.81) before projection
    return (-c_[k] * error.dot(xij) / xij.squaredNorm()) * xij;  // (6.80)
  }

 private:
  PairArray<double> c_;
};

}  // namespace tlsph
