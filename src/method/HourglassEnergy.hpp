// The hourglass penalty as an energy, the conservative form of Ganzenmueller's (6.80)-(6.81):
//   E_hg = 1/4 sum_I sum_J k_IJ |e_IJ|^2,   e_IJ = x_IJ - 1/2 (F_I + F_J) X_IJ,
//   k_IJ = V_I c_IJ (HourglassStiffness.hpp; symmetric in I and J).
// F is the one the scene's penalty compares with: the corrected F or the linear one
// (DeformationGradient.hpp). Its exact force f = -dE_hg/du has two parts:
//   the spring, on u directly:   f_I = -sum_J k_IJ e_IJ
//     (each unordered pair appears twice in the sum, and e_JI = -e_IJ);
//   through F, the hourglass stress  P^hg_I = -1/2 sum_J c_IJ e_IJ (x) X_IJ
//     (dE_hg = sum_I V_I P^hg_I : dF_I), sent through the F's own gradient vectors like P
//     (InternalForce.hpp).
// e_IJ is zero for every affine field (F exact for it), and for quadratic ones too on an F
// exact for those; it turns with x under a rotation, so E_hg is objective.
#pragma once

#include <vector>

#include "method/InternalForce.hpp"
#include "method/ReferenceConfiguration.hpp"
#include "model/Types.hpp"

namespace tlsph {

// e_IJ of pair k = (i, j). Written with x_IJ - X_IJ = u_I - u_J and H = F - 1, the same
// difference without cancelling X_IJ against itself.
template <int D>
Vec<D> hourglassError(const ReferenceConfiguration<D>& ref, Index k, Index i, Index j,
                      const std::vector<Vec<D>>& u, const std::vector<Mat<D>>& F) {
  const Vec<D>& Xij = ref.separation[k];
  const Mat<D> Hmean = 0.5 * (F[i] + F[j]) - Mat<D>::Identity();
  return (u[i] - u[j]) - Hmean * Xij;
}

// E_hg for the pair coefficients c (c_IJ = k_IJ / V_I).
template <int D>
double hourglassEnergy(const ReferenceConfiguration<D>& ref, const PairArray<double>& c,
                       const std::vector<double>& volume, const std::vector<Vec<D>>& u,
                       const std::vector<Mat<D>>& F) {
  const auto& nb = ref.neighbours;
  double E = 0.0;
  for (Index i = 0; i < ref.particleCount(); ++i)
    for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k) {
      const Vec<D> e = hourglassError<D>(ref, k, i, nb.neighbour[k], u, F);
      E += 0.25 * volume[i] * c[k] * e.squaredNorm();
    }
  return E;
}

// The spring part of -dE_hg/du: f_I = -sum_J k_IJ e_IJ.
template <int D>
std::vector<Vec<D>> hourglassSpringForce(const ReferenceConfiguration<D>& ref,
                                         const PairArray<double>& c,
                                         const std::vector<double>& volume,
                                         const std::vector<Vec<D>>& u,
                                         const std::vector<Mat<D>>& F) {
  const auto& nb = ref.neighbours;
  std::vector<Vec<D>> f(ref.particleCount(), Vec<D>::Zero());
  for (Index i = 0; i < ref.particleCount(); ++i)
    for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k)
      f[i] -= volume[i] * c[k] * hourglassError<D>(ref, k, i, nb.neighbour[k], u, F);
  return f;
}

// P^hg_I = -1/2 sum_J c_IJ e_IJ (x) X_IJ: dE_hg/dF_I = V_I P^hg_I.
template <int D>
std::vector<Mat<D>> hourglassStress(const ReferenceConfiguration<D>& ref,
                                    const PairArray<double>& c, const std::vector<Vec<D>>& u,
                                    const std::vector<Mat<D>>& F) {
  const auto& nb = ref.neighbours;
  std::vector<Mat<D>> P(ref.particleCount(), Mat<D>::Zero());
  for (Index i = 0; i < ref.particleCount(); ++i)
    for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k) {
      const Vec<D> e = hourglassError<D>(ref, k, i, nb.neighbour[k], u, F);
      P[i] -= 0.5 * c[k] * e * ref.separation[k].transpose();
    }
  return P;
}

// f += -dE_hg/du: the spring plus P^hg sent through g, the gradient vectors of the F given.
template <int D>
void addHourglassForce(const ReferenceConfiguration<D>& ref, const PairArray<double>& c,
                       const std::vector<double>& volume, const PairArray<Vec<D>>& g,
                       const std::vector<Vec<D>>& u, const std::vector<Mat<D>>& F,
                       std::vector<Vec<D>>& f) {
  const auto spring = hourglassSpringForce<D>(ref, c, volume, u, F);
  for (Index i = 0; i < ref.particleCount(); ++i)
    f[i] += spring[i];
  addStressDivergence<D>(ref.neighbours, g, volume, hourglassStress<D>(ref, c, u, F), f);
}

}  // namespace tlsph
