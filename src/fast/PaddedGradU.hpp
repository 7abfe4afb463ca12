// grad u = sum_J (u_J - u_I) (x) g_IJ of F (6.69), as method/DeformationGradient.hpp, for the
// 3D nodal quadrature with the energy penalty on F: padded, two particles at a time.
// Members of TlsphForces (TlsphForces.hpp), used by its stress pass (StressPass.hpp).
#pragma once

#include <algorithm>

#include "execution/Prefetch.hpp"
#include "fast/Padded.hpp"
#include "fast/TlsphForces.hpp"
#include "model/Types.hpp"

namespace tlsph {

// 3D nodal with the penalty on F: grad u of particles i0 and i1, the sums padded like the
// Taylor fit's (u_J one 256-bit load, a column one 4-wide multiply-add), the two particles'
// pairs interleaved: one particle's three column sums are chains of 4-cycle multiply-adds,
// two particles' six keep the pipes busy. Each column the same products in the
// same order as the one-particle paddedGradU.
template <int D>
[[gnu::always_inline]] inline void TlsphForces<D>::paddedGradU(Index i0, Index i1,
                                                               PaddedMat<D>& gradU0,
                                                               PaddedMat<D>& gradU1) const {
  const Index* offset = ref_.neighbours.offset.data();
  const PaddedVec<D> ui0 = paddedU_[i0], ui1 = paddedU_[i1];
  PaddedMat<D> sum0 = PaddedMat<D>::Zero(), sum1 = PaddedMat<D>::Zero();
  const Vec<D>* g0 = correctedGradient_.row(i0);
  const Vec<D>* g1 = correctedGradient_.row(i1);
  Index k0 = offset[i0], k1 = offset[i1];
  const Index end0 = offset[i0 + 1], end1 = offset[i1 + 1];
  const bool ahead = correctedGradient_.streams();
  for (const Index both = k0 + std::min(end0 - k0, end1 - k1); k0 < both; ++k0, ++k1) {
    addPaddedPair(sum0, ui0, k0, g0++, ahead);
    addPaddedPair(sum1, ui1, k1, g1++, ahead);
  }
  for (; k0 < end0; ++k0)
    addPaddedPair(sum0, ui0, k0, g0++, ahead);
  for (; k1 < end1; ++k1)
    addPaddedPair(sum1, ui1, k1, g1++, ahead);
  gradU0 = sum0;
  gradU1 = sum1;
}

// One particle's (the last of a chunk with an odd count).
template <int D>
[[gnu::always_inline]] inline void TlsphForces<D>::paddedGradU(Index i, PaddedMat<D>& gradU) const {
  const PaddedVec<D> ui = paddedU_[i];
  PaddedMat<D> sum = PaddedMat<D>::Zero();
  const Vec<D>* g = correctedGradient_.row(i);
  const bool ahead = correctedGradient_.streams();
  for (Index k = ref_.neighbours.offset[i]; k < ref_.neighbours.offset[i + 1]; ++k)
    addPaddedPair(sum, ui, k, g++, ahead);
  gradU = sum;
}

// Pair k's term (u_J - u_I) (x) g_IJ of grad u, padded, g its gradient vector (ahead: the
// rows stream, SharedRows::streams).
template <int D>
[[gnu::always_inline]] inline void TlsphForces<D>::addPaddedPair(PaddedMat<D>& sum,
                                                                 const PaddedVec<D>& ui, Index k,
                                                                 const Vec<D>* g,
                                                                 bool ahead) const {
  if (ahead) prefetchAhead(g);
  const PaddedVec<D> du = paddedU_[ref_.neighbours.neighbour[k]] - ui;
  for (int m = 0; m < D; ++m)
    sum.col(m).noalias() += du * (*g)[m];
}

}  // namespace tlsph
