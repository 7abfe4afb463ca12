// The second-order (Taylor) term of the strain energy's quadrature, plainly; the fast pass
// fuses it into the force loops. E = sum_I V_I psi(F_I) is the midpoint rule on the
// particles' cells: for an energy density varying quadratically across a cell it misses
// V_I l_I^2 / 24 sum_a d^2 psi / dX_a^2 (l_I = V_I^(1/d)), in bending the fraction 1/n^2 of
// the bending energy with n particles through the thickness. The term adds it back:
//   E_q = sum_I V_I c_I / 2 sum_a e_a : C0 : e_a,   c_I = l_I^2 / 12,
//   e_a = sym(F_I^T G_a),   G_a = dF/dX_a,   G_a(:, b) = sum_J (u_J - u_I) S_IJ(a, b),
// C0 the material's small-strain stiffness (lambda, mu), S_IJ the second-derivative vectors
// of the same weighted least-squares quadratic fit that gives the quadratic F. For the
// linear-elastic material, whose energy is that of the small strain, e_a = sym(G_a).
// Its exact gradient, with sigma_a = c_I C0 : e_a:
//   through F:    P^q_I = sum_a G_a sigma_a    (added to P, sent through g_IJ)
//   through G_a:  the hyperstress R_Ia = F_I sigma_a (sigma_a alone for linear elasticity),
//                 dE_q = sum_I V_I sum_ab R_Ia(:, b) . dG_a(:, b), sent through S_IJ as P is
//                 through g_IJ: f_J -= V_I sum_a R_Ia S_IJ(:, a), f_I += the same.
// e_a is objective and zero for every affine field, so E_q >= 0 vanishes on rigid motions.
// Only with the quadratic correction; particles on its linear fallback and passive ones carry
// no term.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "materials/Material.hpp"
#include "method/ReferenceConfiguration.hpp"
#include "model/Types.hpp"

namespace tlsph {

// Per particle: the term's weight c_I = l_I^2 / 12 and its material's small-strain stiffness
// C0 (lambda, mu); passive particles carry no term (weight 0).
struct TaylorTermConstants {
  std::vector<double> weight, lambda, mu;
  std::vector<std::uint8_t> smallStrain;  // linear-elastic material: e_a = sym(G_a)
};
template <int D>
TaylorTermConstants taylorTermConstants(const std::vector<Material>& materials,
                                        const std::vector<std::uint16_t>& materialOf,
                                        const std::vector<double>& volume,
                                        const std::vector<std::uint8_t>& passive);

// S_IJ of each of particle i's pairs (in its list's order): the second-derivative vectors of the
// weighted least-squares quadratic fit of ReferenceConfiguration's quadratic correction.
template <int D>
std::vector<Mat<D>> fitSecondDerivatives(const ReferenceConfiguration<D>& ref,
                                         const std::vector<double>& volume, Index i);

template <int D>
class TaylorCorrection {
 public:
  using Gradients = std::array<Mat<D>, D>;  // G_a = dF/dX_a, a = 0..D-1 (likewise R_a)

  // Fits the second-derivative vectors S_IJ (TaylorCorrection.cpp: the fit's moment matrices
  // are inverted there, compiled once; the fast pass's set-up calls the same functions).
  TaylorCorrection(const ReferenceConfiguration<D>& ref, const std::vector<Material>& materials,
                   const std::vector<std::uint16_t>& materialOf, const std::vector<double>& volume,
                   const std::vector<std::uint8_t>& passive = {});

  // S_IJ of pair k: d^2 u / dX_a dX_b at I = sum_J (u_J - u_I) S_IJ(a, b).
  const Mat<D>& secondDerivativeVector(Index k) const { return S_[k]; }

  // G_a(:, b) = d^2 u / dX_a dX_b at particle i.
  Gradients secondGradients(Index i, const std::vector<Vec<D>>& u) const {
    const auto& nb = ref_.neighbours;
    Gradients G;
    for (auto& Ga : G)
      Ga.setZero();
    for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k) {
      const Vec<D> du = u[nb.neighbour[k]] - u[i];
      for (int a = 0; a < D; ++a)
        G[a] += du * S_[k].row(a);
    }
    return G;
  }

  // e_a = sym(F^T G_a), or sym(G_a) for the linear-elastic material.
  Mat<D> strain(Index i, const Mat<D>& F, const Mat<D>& Ga) const {
    const Mat<D> A = smallStrain_[i] ? Ga : Mat<D>(F.transpose() * Ga);
    return 0.5 * (A + A.transpose());
  }

  // C0 : e
  Mat<D> smallStrainStress(Index i, const Mat<D>& e) const {
    return lambda_[i] * e.trace() * Mat<D>::Identity() + 2.0 * mu_[i] * e;
  }

  // E_q for the F and G of every particle.
  double energy(const std::vector<Mat<D>>& F, const std::vector<Gradients>& G) const {
    double E = 0.0;
    for (Index i = 0; i < ref_.particleCount(); ++i)
      for (int a = 0; a < D; ++a) {
        const Mat<D> e = strain(i, F[i], G[i][a]);
        E += 0.5 * volume_[i] * weight_[i] * (smallStrainStress(i, e).array() * e.array()).sum();
      }
    return E;
  }

  // P^q_I = sum_a G_a sigma_a (none for the linear-elastic material, whose e_a has no F).
  Mat<D> stress(Index i, const Mat<D>& F, const Gradients& G) const {
    Mat<D> Pq = Mat<D>::Zero();
    if (smallStrain_[i]) return Pq;
    for (int a = 0; a < D; ++a)
      Pq += G[a] * (weight_[i] * smallStrainStress(i, strain(i, F, G[a])));
    return Pq;
  }

  // R_Ia = F_I sigma_a (sigma_a for the linear-elastic material).
  Gradients hyperstress(Index i, const Mat<D>& F, const Gradients& G) const {
    Gradients R;
    for (int a = 0; a < D; ++a) {
      const Mat<D> sigma = weight_[i] * smallStrainStress(i, strain(i, F, G[a]));
      R[a] = smallStrain_[i] ? sigma : Mat<D>(F * sigma);
    }
    return R;
  }

  // The linearisation of stress() and hyperstress() about (F, G) in a direction whose
  // displacement gradient is dH and second gradients dG (the tangent stiffness's part of the
  // term): with sigma_a = c_I C0 : e_a and de_a = sym(dH^T G_a + F^T dG_a) (sym(dG_a) for
  // the linear-elastic material),
  //   dP^q = sum_a (dG_a sigma_a + G_a dsigma_a),   dR_a = dH sigma_a + F dsigma_a.
  struct Linearised {
    Mat<D> stress;
    Gradients hyperstress;
  };
  Linearised linearised(Index i, const Mat<D>& F, const Gradients& G, const Mat<D>& dH,
                        const Gradients& dG) const {
    Linearised d;
    d.stress.setZero();
    for (int a = 0; a < D; ++a) {
      const Mat<D> sigma = weight_[i] * smallStrainStress(i, strain(i, F, G[a]));
      const Mat<D> A =
          smallStrain_[i] ? dG[a] : Mat<D>(dH.transpose() * G[a] + F.transpose() * dG[a]);
      const Mat<D> dsigma = weight_[i] * smallStrainStress(i, 0.5 * (A + A.transpose()));
      if (smallStrain_[i]) {
        d.hyperstress[a] = dsigma;
      } else {
        d.stress += dG[a] * sigma + G[a] * dsigma;
        d.hyperstress[a] = dH * sigma + F * dsigma;
      }
    }
    return d;
  }

  // f -= the part of dE_q/du through G: each pair sends V_I sum_a R_Ia S_IJ(:, a) to J and
  // takes it from I (the pair sum of InternalForce.hpp, one order up).
  void addHyperstressForce(const std::vector<Mat<D>>& F, const std::vector<Gradients>& G,
                           std::vector<Vec<D>>& f) const {
    const auto& nb = ref_.neighbours;
    for (Index i = 0; i < ref_.particleCount(); ++i) {
      const Gradients R = hyperstress(i, F[i], G[i]);
      for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k) {
        Vec<D> sent = Vec<D>::Zero();
        for (int a = 0; a < D; ++a)
          sent += R[a] * S_[k].col(a);
        sent *= volume_[i];
        f[nb.neighbour[k]] -= sent;
        f[i] += sent;
      }
    }
  }

 private:
  const ReferenceConfiguration<D>& ref_;
  const std::vector<double>& volume_;
  PairArray<Mat<D>> S_;                    // S_IJ, symmetric
  std::vector<double> weight_;             // c_I = l_I^2 / 12; 0 where there is no term
  std::vector<double> lambda_, mu_;        // C0
  std::vector<std::uint8_t> smallStrain_;  // linear-elastic material: e_a = sym(G_a)
};

extern template class TaylorCorrection<2>;
extern template class TaylorCorrection<3>;

}  // namespace tlsph
