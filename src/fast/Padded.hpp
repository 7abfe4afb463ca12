// No formula of method/: the pair loops' gathered values with their 3-vectors padded to 4
// doubles. A column of a padded 3 x C matrix is one 256-bit register, so S_J t_IJ, R_J T_IJ,
// F_J X_IJ and w_IJ X_IJ^T are one vector multiply-add per column instead of a 2-wide and a
// scalar one (20 % fewer cycles per step). The fourth row is zero and
// stays zero: only the top D rows are ever written (topRows()). In 2D nothing is padded: a
// padded type is the plain one.
#pragma once

#include <Eigen/Core>
#ifdef __AVX__
#include <immintrin.h>
#endif

#include "model/Types.hpp"

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

// The top D x D of m transposed, with a zero fourth row (m's must be zero too). In 3D with AVX
// this stays in registers (seven shuffles): Eigen's transpose assembles the columns on the stack
// from 64-bit stores, and reloading them as 256-bit words stalls store-to-load forwarding
// (measured in TaylorQuadrature's stresses).
template <int D>
PaddedMat<D, D> transposed(const PaddedMat<D, D>& m) {
#ifdef __AVX__
  if constexpr (D == 3) {
    const __m256d c0 = _mm256_loadu_pd(m.col(0).data());  // m00 m10 m20 0
    const __m256d c1 = _mm256_loadu_pd(m.col(1).data());
    const __m256d c2 = _mm256_loadu_pd(m.col(2).data());
    const __m256d zero = _mm256_setzero_pd();
    const __m256d t0 = _mm256_unpacklo_pd(c0, c1);    // m00 m01 | m20 m21
    const __m256d t1 = _mm256_unpackhi_pd(c0, c1);    // m10 m11 | 0 0
    const __m256d t2 = _mm256_unpacklo_pd(c2, zero);  // m02 0 | m22 0
    const __m256d t3 = _mm256_unpackhi_pd(c2, zero);  // m12 0 | 0 0
    PaddedMat<D, D> t;
    _mm256_storeu_pd(t.col(0).data(), _mm256_permute2f128_pd(t0, t2, 0x20));
    _mm256_storeu_pd(t.col(1).data(), _mm256_permute2f128_pd(t1, t3, 0x20));
    _mm256_storeu_pd(t.col(2).data(), _mm256_permute2f128_pd(t0, t2, 0x31));
    return t;
  }
#endif
  PaddedMat<D, D> t = PaddedMat<D, D>::Zero();
  t.template topRows<D>() = m.template topRows<D>().transpose();
  return t;
}

// out = s with m added to its top D rows, column by column. In 3D with AVX each column of m is
// put together in a register (its entries wherever GCC holds them), added to s's as one 256-bit
// word and stored as one: written with Eigen, GCC moved such sums through the stack in 16- and
// 8-byte pieces and reloaded them as 256-bit words, stalling store-to-load forwarding (the
// Taylor F pass). The same sums, the same bits.
template <int D>
void addTop(const PaddedMat<D, D>& s, const Mat<D>& m, PaddedMat<D, D>& out) {
#ifdef __AVX__
  if constexpr (D == 3) {
    for (int c = 0; c < D; ++c) {
      const __m256d column = _mm256_set_pd(0.0, m(2, c), m(1, c), m(0, c));
      _mm256_storeu_pd(out.col(c).data(), _mm256_add_pd(_mm256_loadu_pd(s.col(c).data()), column));
    }
    return;
  }
#endif
  out = s;
  out.template topRows<D>() += m;
}

}  // namespace tlsph
