// TaylorCorrection's set-up, compiled once for 2D and 3D: the quadratic fit's moment matrices
// are inverted here with Eigen's dense eigensolver, out of every file that evaluates the
// forces. The fast pass (fast/TaylorQuadrature.cpp) is set up by the same two functions.
#include "method/TaylorCorrection.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <variant>

#include "model/Errors.hpp"

namespace tlsph {

template <int D>
TaylorTermConstants<D> taylorTermConstants(const std::vector<Material>& materials,
                                           const std::vector<std::uint16_t>& materialOf,
                                           const std::vector<double>& volume,
                                           const std::vector<std::uint8_t>& passive,
                                           const QuadratureMoments<D>& moments) {
  const std::size_t n = volume.size();
  if (!moments.lattice() && (moments.offset.size() != n || moments.spread.size() != n))
    throw SetupError("the particles' quadrature moments are not one per particle");
  TaylorTermConstants<D> c;
  c.offset.assign(n, Vec<D>::Zero());
  c.spread.assign(n, Mat<D>::Zero());
  c.lambda.assign(n, 0.0);
  c.mu.assign(n, 0.0);
  c.smallStrain.assign(n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    if (!passive.empty() && passive[i]) continue;
    const Material& material = materials[materialOf[i]];
    if (moments.lattice()) {
      c.spread[i] = latticeSpread<D>(volume[i]);
    } else {
      c.offset[i] = moments.offset[i];
      c.spread[i] = moments.spread[i];
    }
    c.lambda[i] = elasticConstants(material).lambda;
    c.mu[i] = elasticConstants(material).mu;
    c.smallStrain[i] = std::holds_alternative<LinearElastic>(material);
  }
  return c;
}

// The fit through particle i's value, with the offsets scaled by l = V_I^(1/d) for
// conditioning: u_J - u_I ~ c . p(-X_IJ / l) weighted by V_J W_IJ, so
// c = M^{-1} sum_J V_J W_IJ p_J (u_J - u_I); the quadratic coefficients give the second
// derivatives (twice the coefficient on the diagonal, d_a^2 being the monomial).
template <int D>
std::vector<Mat<D>> fitSecondDerivatives(const ReferenceConfiguration<D>& ref,
                                         const std::vector<double>& volume, Index i) {
  constexpr int T = kQuadraticTerms<D>;
  using Moment = Eigen::Matrix<double, T, T>;
  using Basis = Eigen::Matrix<double, T, 1>;
  const auto& nb = ref.neighbours;
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
  std::vector<Mat<D>> S(nb.count(i));
  for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k) {
    const Basis c = (volume[nb.neighbour[k]] * ref.kernelValue[k]) * (Minv * basis(k));
    Mat<D>& Sk = S[k - nb.offset[i]];
    int t = D;  // the quadratic monomials d_a d_b, a <= b, follow the linear ones
    for (int a = 0; a < D; ++a)
      for (int b = a; b < D; ++b, ++t) {
        const double v = c[t] / (l * l);
        Sk(a, b) = Sk(b, a) = a == b ? 2.0 * v : v;
      }
  }
  return S;
}

template <int D>
TaylorCorrection<D>::TaylorCorrection(const ReferenceConfiguration<D>& ref,
                                      const std::vector<Material>& materials,
                                      const std::vector<std::uint16_t>& materialOf,
                                      const std::vector<double>& volume,
                                      const std::vector<std::uint8_t>& passive,
                                      const QuadratureMoments<D>& moments)
    : ref_(ref), volume_(volume) {
  const auto& nb = ref.neighbours;
  TaylorTermConstants<D> c =
      taylorTermConstants<D>(materials, materialOf, volume, passive, moments);
  offset_ = std::move(c.offset);
  spread_ = std::move(c.spread);
  lambda_ = std::move(c.lambda);
  mu_ = std::move(c.mu);
  smallStrain_ = std::move(c.smallStrain);
  S_.assign(nb.pairCount(), Mat<D>::Zero());
  std::vector<std::uint8_t> fallback(ref.particleCount(), 0);
  for (Index i : ref.linearFallback)
    fallback[i] = 1;
  for (Index i = 0; i < ref.particleCount(); ++i)
    if (ref.correction == GradientCorrection::Quadratic && !fallback[i] && nb.count(i) > 0) {
      const std::vector<Mat<D>> S = fitSecondDerivatives<D>(ref, volume, i);
      std::copy(S.begin(), S.end(), S_.begin() + nb.offset[i]);
    }
}

template TaylorTermConstants<2> taylorTermConstants<2>(const std::vector<Material>&,
                                                       const std::vector<std::uint16_t>&,
                                                       const std::vector<double>&,
                                                       const std::vector<std::uint8_t>&,
                                                       const QuadratureMoments<2>&);
template TaylorTermConstants<3> taylorTermConstants<3>(const std::vector<Material>&,
                                                       const std::vector<std::uint16_t>&,
                                                       const std::vector<double>&,
                                                       const std::vector<std::uint8_t>&,
                                                       const QuadratureMoments<3>&);
template std::vector<Mat<2>> fitSecondDerivatives<2>(const ReferenceConfiguration<2>&,
                                                     const std::vector<double>&, Index);
template std::vector<Mat<3>> fitSecondDerivatives<3>(const ReferenceConfiguration<3>&,
                                                     const std::vector<double>&, Index);
template class TaylorCorrection<2>;
template class TaylorCorrection<3>;

}  // namespace tlsph
