// E_q of method/TaylorCorrection.hpp: TaylorQuadrature's set-up (see the header), compiled once for
// 2D and 3D: the fit's moment matrices are inverted here (Eigen's dense eigensolver), out of every
// file that includes the force pass. The fit is the one of method/TaylorCorrection.cpp, written
// again in this unit: compiled elsewhere its rounding differs (contraction into fused
// multiply-adds), and every run's bits with it. Eigen's small products inlined in the per-particle
// part of the force pass (stressAt), as in TlsphForces.cpp.
#ifndef EIGEN_STRONG_INLINE
#define EIGEN_STRONG_INLINE inline __attribute__((always_inline))
#endif
#include "fast/TaylorQuadrature.hpp"

#include "model/Errors.hpp"

namespace tlsph {

template <int D>
TaylorQuadrature<D>::TaylorQuadrature(const ReferenceConfiguration<D>& ref,
                                      const std::vector<Material>& materials,
                                      const std::vector<std::uint16_t>& materialOf,
                                      const std::vector<double>& volume,
                                      const std::vector<std::uint8_t>& passive,
                                      const QuadratureMoments<D>& moments)
    : ref_(ref), volume_(volume) {
  const auto& nb = ref.neighbours;
  const Index n = ref.particleCount();
  // Built whole, then kept as shared rows (SharedRows.hpp): the pair loops stream only the
  // distinct rows.
  PairArray<Fit> fit(nb.pairCount());
  for (std::size_t k = 0; k < fit.size(); ++k)  // S_IJ = 0 unless the fit below sets it
    fit[k] << ref.correctedGradient[k].transpose(), Sym::Zero().transpose();
  sum_.assign(n, Sym::Zero());
  weight_.assign(n, 0.0);
  lambda_.assign(n, 0.0);
  mu_.assign(n, 0.0);
  smallStrain_.assign(n, 0);
  general_ = !moments.lattice();
  if (general_) {
    if (moments.offset.size() != std::size_t(n) || moments.spread.size() != std::size_t(n))
      throw SetupError("the particles' quadrature moments are not one per particle");
    offset_.assign(n, Vec<D>::Zero());
    spread_.assign(n, Mat<D>::Zero());
  }
  std::vector<std::uint8_t> fallback(n, 0);
  for (Index i : ref.linearFallback)
    fallback[i] = 1;
  constexpr int T = kQuadraticTerms<D>;
  using Moment = Eigen::Matrix<double, T, T>;
  using Basis = Eigen::Matrix<double, T, 1>;
  for (Index i = 0; i < n; ++i) {
    const bool energy = passive.empty() || !passive[i];
    if (energy) {
      const auto& c = elasticConstants(materials[materialOf[i]]);
      const double l = std::pow(volume[i], 1.0 / D);
      weight_[i] = l * l / 12.0;  // with general moments only a mark that the term is on
      if (general_) {
        offset_[i] = moments.offset[i];
        spread_[i] = moments.spread[i];
      }
      lambda_[i] = c.lambda;
      mu_[i] = c.mu;
      smallStrain_[i] = std::holds_alternative<LinearElastic>(materials[materialOf[i]]);
    }
    // (no list: a particle this rank keeps no pair data for)
    if (ref.correction != GradientCorrection::Quadratic || fallback[i] || nb.count(i) == 0)
      continue;
    // The fit of ReferenceConfiguration (scale-free: the basis is scaled by l for conditioning).
    const double l = std::pow(volume[i], 1.0 / D);
    auto basis = [&](Index k) -> Basis { return quadraticBasis<D>(-ref.separation[k] / l); };
    Moment M = Moment::Zero();
    for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k) {
      const Basis p = basis(k);
      M.noalias() += (volume[nb.neighbour[k]] * ref.kernelValue[k]) * p * p.transpose();
    }
    const Eigen::SelfAdjointEigenSolver<Moment> eigen(M);
    const Moment Minv = eigen.eigenvectors() * eigen.eigenvalues().cwiseInverse().asDiagonal() *
                        eigen.eigenvectors().transpose();
    for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k) {
      const Basis c = (volume[nb.neighbour[k]] * ref.kernelValue[k]) * (Minv * basis(k));
      Sym s;
      int t = 0;
      for (int a = 0; a < D; ++a)
        for (int b = a; b < D; ++b, ++t) {
          const double v = c[D + t] / (l * l);
          s[t] = a == b ? 2.0 * v : v;  // S_IJ(a, b)
        }
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
