// TaylorCorrection's set-up, compiled once for 2D and 3D: the quadratic fit's moment matrices
// are inverted here with Eigen's dense eigensolver (the same inverse as the fast pass's, so the
// two agree to rounding), out of every file that evaluates the forces.
#include "method/TaylorCorrection.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <variant>

namespace tlsph {

template <int D>
TaylorCorrection<D>::TaylorCorrection(const ReferenceConfiguration<D>& ref,
                                      const std::vector<Material>& materials,
                                      const std::vector<std::uint16_t>& materialOf,
                                      const std::vector<double>& volume,
                                      const std::vector<std::uint8_t>& passive)
    : ref_(ref), volume_(volume) {
  const auto& nb = ref.neighbours;
  const Index n = ref.particleCount();
  S_.assign(nb.pairCount(), Mat<D>::Zero());
  weight_.assign(n, 0.0);
  lambda_.assign(n, 0.0);
  mu_.assign(n, 0.0);
  smallStrain_.assign(n, 0);
  std::vector<std::uint8_t> fallback(n, 0);
  for (Index i : ref.linearFallback)
    fallback[i] = 1;
  for (Index i = 0; i < n; ++i) {
    const double l = std::pow(volume[i], 1.0 / D);
    if (passive.empty() || !passive[i]) {
      const Material& material = materials[materialOf[i]];
      weight_[i] = l * l / 12.0;
      lambda_[i] = elasticConstants(material).lambda;
      mu_[i] = elasticConstants(material).mu;
      smallStrain_[i] = std::holds_alternative<LinearElastic>(material);
    }
    if (ref.correction == GradientCorrection::Quadratic && !fallback[i] && nb.count(i) > 0)
      fitSecondDerivatives(i, l);
  }
}

// The fit of ReferenceConfiguration's quadratic correction through particle i's value, with
// the offsets scaled by l for conditioning: u_J - u_I ~ c . p(-X_IJ / l) weighted by V_J W_IJ,
// so c = M^{-1} sum_J V_J W_IJ p_J (u_J - u_I); the quadratic coefficients give the second
// derivatives (twice the coefficient on the diagonal, d_a^2 being the monomial).
template <int D>
void TaylorCorrection<D>::fitSecondDerivatives(Index i, double l) {
  constexpr int T = kQuadraticTerms<D>;
  using Moment = Eigen::Matrix<double, T, T>;
  using Basis = Eigen::Matrix<double, T, 1>;
  const auto& nb = ref_.neighbours;
  auto weight = [&](Index k) { return volume_[nb.neighbour[k]] * ref_.kernelValue[k]; };
  auto basis = [&](Index k) -> Basis { return quadraticBasis<D>(-ref_.separation[k] / l); };
  Moment M = Moment::Zero();
  for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k)
    M += weight(k) * basis(k) * basis(k).transpose();
  const Eigen::SelfAdjointEigenSolver<Moment> eigen(M);
  const Moment Minv = eigen.eigenvectors() * eigen.eigenvalues().cwiseInverse().asDiagonal() *
                      eigen.eigenvectors().transpose();
  for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k) {
    const Basis c = weight(k) * (Minv * basis(k));
    int t = D;  // the quadratic monomials d_a d_b, a <= b, follow the linear ones
    for (int a = 0; a < D; ++a)
      for (int b = a; b < D; ++b, ++t) {
        const double v = c[t] / (l * l);
        S_[k](a, b) = S_[k](b, a) = a == b ? 2.0 * v : v;
      }
  }
}

template class TaylorCorrection<2>;
template class TaylorCorrection<3>;

}  // namespace tlsph
