// E_q of method/TaylorCorrection.hpp: TaylorQuadrature's set-up (see the header), compiled once for
// 2D and 3D, from method/TaylorCorrection's constants and quadratic fit, kept in the pass's
// layout. Eigen's small products inlined in the per-particle part of the force pass (stressAt),
// as in TlsphForces.cpp.
#ifndef EIGEN_STRONG_INLINE
#define EIGEN_STRONG_INLINE inline __attribute__((always_inline))
#endif
#include "fast/TaylorQuadrature.hpp"

#include <utility>

#include "method/TaylorCorrection.hpp"

namespace tlsph {

template <int D>
TaylorQuadrature<D>::TaylorQuadrature(const ReferenceConfiguration<D>& ref,
                                      const std::vector<Material>& materials,
                                      const std::vector<std::uint16_t>& materialOf,
                                      const std::vector<double>& volume,
                                      const std::vector<std::uint8_t>& passive)
    : ref_(ref), volume_(volume) {
  const auto& nb = ref.neighbours;
  const Index n = ref.particleCount();
  // Built whole, then kept as shared rows (SharedRows.hpp): the pair loops stream only the
  // distinct rows.
  PairArray<Fit> fit(nb.pairCount());
  for (std::size_t k = 0; k < fit.size(); ++k)  // S_IJ = 0 unless the fit below sets it
    fit[k] << ref.correctedGradient[k].transpose(), Sym::Zero().transpose();
  sum_.assign(n, Sym::Zero());
  TaylorTermConstants c = taylorTermConstants<D>(materials, materialOf, volume, passive);
  weight_ = std::move(c.weight);
  lambda_ = std::move(c.lambda);
  mu_ = std::move(c.mu);
  smallStrain_ = std::move(c.smallStrain);
  std::vector<std::uint8_t> fallback(n, 0);
  for (Index i : ref.linearFallback)
    fallback[i] = 1;
  for (Index i = 0; i < n; ++i) {
    // (no list: a particle this rank keeps no pair data for)
    if (ref.correction != GradientCorrection::Quadratic || fallback[i] || nb.count(i) == 0)
      continue;
    const std::vector<Mat<D>> S = fitSecondDerivatives<D>(ref, volume, i);
    for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k) {
      const Mat<D>& Sk = S[k - nb.offset[i]];
      Sym s;
      int t = 0;
      for (int a = 0; a < D; ++a)
        for (int b = a; b < D; ++b, ++t)
          s[t] = Sk(a, b);
      fit[k].template tail<P>() = s.transpose();
      sum_[i] += s;
    }
  }
  // T_IJ = (V_J / V_I) S_JI
  PairArray<Sym> reverse = reversePairValuesOf<Sym>(
      nb, [&](Index k) -> Sym { return fit[k].template tail<P>().transpose(); }, volume,
      ref.rows());
  fit_ = SharedRows<Fit>(nb, std::move(fit));
  reverse_ = SharedRows<Sym>(nb, std::move(reverse));
  G_.assign(n, SymMatrix::Zero());
  R_.assign(n, PaddedSymMatrix::Zero());
  force_.assign(n, Vec<D>::Zero());
}

template class TaylorQuadrature<2>;
template class TaylorQuadrature<3>;

}  // namespace tlsph
