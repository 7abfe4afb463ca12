// The deformation gradient (6.69), as the plain reference of what the fast passes compute:
//   F_I = 1 + sum_J (u_J - u_I) (x) g_IJ
// with the gradient vectors g_IJ of ReferenceConfiguration. With the linear correction
// g_IJ = L_I^{-T} V_J gradW_IJ, so F is exact for every affine field; with the quadratic
// correction g_IJ is the quadratic fit's, exact for quadratic fields. The linear vectors are
// also kept then, for the hourglass penalty that compares with the linear F.
#pragma once

#include <vector>

#include "method/ReferenceConfiguration.hpp"
#include "model/Types.hpp"

namespace tlsph {

// F of particle i for the gradient vectors g (one per pair, in the CSR order of nb).
template <int D>
Mat<D> deformationGradientAt(const NeighbourList& nb, const PairArray<Vec<D>>& g,
                             const std::vector<Vec<D>>& u, Index i) {
  Mat<D> F = Mat<D>::Identity();
  for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k) {
    const Index j = nb.neighbour[k];
    F += (u[j] - u[i]) * g[k].transpose();  // (6.69)
  }
  return F;
}

// F of every particle for the gradient vectors g.
// H_I = F_I - 1 = sum_J (u_J - u_I) (x) g_IJ, summed without the 1: (6.69) for a direction
// (a mode shape, a tangent's dH), where 1 + dH would round dH off.
template <int D>
Mat<D> displacementGradientAt(const NeighbourList& nb, const PairArray<Vec<D>>& g,
                              const std::vector<Vec<D>>& u, Index i) {
  Mat<D> H = Mat<D>::Zero();
  for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k)
    H += (u[nb.neighbour[k]] - u[i]) * g[k].transpose();
  return H;
}

template <int D>
std::vector<Mat<D>> deformationGradients(const ReferenceConfiguration<D>& ref,
                                         const PairArray<Vec<D>>& g, const std::vector<Vec<D>>& u) {
  const Index n = ref.particleCount();
  std::vector<Mat<D>> F(n);
#pragma omp parallel for schedule(static)
  for (Index i = 0; i < n; ++i)
    F[i] = deformationGradientAt<D>(ref.neighbours, g, u, i);
  return F;
}

// The scene's F: through the corrected gradient vectors (linear or quadratic correction).
template <int D>
std::vector<Mat<D>> deformationGradients(const ReferenceConfiguration<D>& ref,
                                         const std::vector<Vec<D>>& u) {
  return deformationGradients<D>(ref, ref.correctedGradient, u);
}

// The linear-corrected gradient vectors L_I^{-T} w_IJ: kept apart only with the quadratic
// correction; with the linear one they are the corrected vectors themselves.
template <int D>
const PairArray<Vec<D>>& linearGradientVectors(const ReferenceConfiguration<D>& ref) {
  return ref.linearGradient.empty() ? ref.correctedGradient : ref.linearGradient;
}

}  // namespace tlsph
