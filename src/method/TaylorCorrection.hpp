// The second-order (Taylor) term of the strain energy's quadrature, plainly; the fast pass
// fuses it into the force loops. Each particle stands for its weight w_I, a partition of unity
// over the body (its lattice cell; a mesh node's hat), and E = sum_I V_I psi(F_I) takes psi
// constant across it. Expanding psi about X_I,
//   int w_I psi dV = V_I [psi_I + mu_a d psi/dX_a + 1/2 N_ab d^2 psi/dX_a dX_b]
// exactly for a quadratic psi, with the weight's moments mu_I (the offset of its centroid) and
// N_I (its second moment about X_I) of model/QuadratureMoments.hpp. The term adds the two
// missing parts for the small-strain surrogate phi = 1/2 E : C0 : E of the energy density,
// whose derivatives are d phi/dX_a = (C0 : E) : e_a and, up to the third derivatives of u,
// d^2 phi/dX_a dX_b = e_a : C0 : e_b:
//   E_q = sum_I V_I [1/2 sum_ab N_ab e_a : C0 : e_b + sum_a mu_a (C0 : E) : e_a],
//   E = 1/2 (F^T F - 1),  e_a = dE/dX_a = sym(F_I^T G_a),  G_a = dF/dX_a,
//   G_a(:, b) = sum_J (u_J - u_I) S_IJ(a, b),
// C0 the material's small-strain stiffness (lambda, mu), S_IJ the second-derivative vectors of
// the same weighted least-squares quadratic fit that gives the quadratic F. For the
// linear-elastic material, whose energy is that of the small strain, E = sym(F - 1) and
// e_a = sym(G_a). On a lattice cell, mu = 0 and N = c_I 1 (c_I = l_I^2 / 12, l_I = V_I^(1/d)):
// E_q = sum_I V_I c_I / 2 sum_a e_a : C0 : e_a, in bending the fraction 1/n^2 of the bending
// energy with n particles through the thickness that the midpoint rule misses.
// Its exact gradient, with sigma_a = sum_b N_ab C0 : e_b + mu_a C0 : E and
// tau = sum_a mu_a C0 : e_a:
//   through F:    P^q_I = sum_a G_a sigma_a + F_I tau    (tau for linear elasticity; added to
//                 P, sent through g_IJ)
//   through G_a:  the hyperstress R_Ia = F_I sigma_a (sigma_a alone for linear elasticity),
//                 dE_q = sum_I V_I sum_ab R_Ia(:, b) . dG_a(:, b), sent through S_IJ as P is
//                 through g_IJ: f_J -= V_I sum_a R_Ia S_IJ(:, a), f_I += the same.
// E and e_a are objective and zero for every rigid motion, e_a for every affine field: E_q
// vanishes on both. Completing the square, the bracket is phi(E + mu_a e_a) - phi(E) +
// 1/2 (N - mu mu^T)_ab e_a : C0 : e_b with N - mu mu^T the weight's central second moment
// (positive semidefinite), so that E + E_q stays positive for small strains.
// Only with the quadratic correction; particles on its linear fallback and passive ones carry
// no term.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "materials/Material.hpp"
#include "method/ReferenceConfiguration.hpp"
#include "model/QuadratureMoments.hpp"
#include "model/Types.hpp"

namespace tlsph {

// Per particle: the moments of its weight (mu_I, N_I; a lattice cell's when `moments` is
// empty) and its material's small-strain stiffness C0 (lambda, mu); passive particles carry no
// term (zero moments).
template <int D>
struct TaylorTermConstants {
  std::vector<Vec<D>> offset;  // mu_I
  std::vector<Mat<D>> spread;  // N_I
  std::vector<double> lambda, mu;
  std::vector<std::uint8_t> smallStrain;  // linear-elastic material: e_a = sym(G_a)
};
template <int D>
TaylorTermConstants<D> taylorTermConstants(const std::vector<Material>& materials,
                                           const std::vector<std::uint16_t>& materialOf,
                                           const std::vector<double>& volume,
                                           const std::vector<std::uint8_t>& passive,
                                           const QuadratureMoments<D>& moments);

// S_IJ of each of particle i's pairs (in its list's order): the second-derivative vectors of the
// weighted least-squares quadratic fit of ReferenceConfiguration's quadratic correction.
template <int D>
std::vector<Mat<D>> fitSecondDerivatives(const ReferenceConfiguration<D>& ref,
                                         const std::vector<double>& volume, Index i);

// One particle's stresses of the term at (F, G), given its constants (mu, N, lambda, mu_lame,
// small: linear-elastic): C0 : e_a and C0 : E, and from them
//   sigma_a = sum_b N_ab C0 : e_b + mu_a C0 : E,   tau = sum_a mu_a C0 : e_a;
// the plain term and the fast pass (fast/TaylorQuadrature.hpp) both call it.
template <int D>
struct TaylorStresses {
  std::array<Mat<D>, D> s, sigma;  // C0 : e_a, sigma_a
  Mat<D> S, tau;                   // C0 : E, tau
};
template <int D>
TaylorStresses<D> taylorTermStresses(const Vec<D>& offset, const Mat<D>& spread, double lambda,
                                     double mu, bool small, const Mat<D>& F,
                                     const std::array<Mat<D>, D>& G) {
  auto C0 = [&](const Mat<D>& A) -> Mat<D> {  // C0 : sym(A)
    const Mat<D> e = 0.5 * (A + A.transpose());
    return lambda * e.trace() * Mat<D>::Identity() + 2.0 * mu * e;
  };
  TaylorStresses<D> t;
  for (int a = 0; a < D; ++a)
    t.s[a] = C0(small ? G[a] : Mat<D>(F.transpose() * G[a]));
  const Mat<D> I = Mat<D>::Identity();
  t.S = C0(small ? Mat<D>(F - I) : Mat<D>(0.5 * (F.transpose() * F - I)));
  t.tau.setZero();
  for (int a = 0; a < D; ++a) {
    t.sigma[a] = offset[a] * t.S;
    for (int b = 0; b < D; ++b)
      t.sigma[a] += spread(a, b) * t.s[b];
    t.tau += offset[a] * t.s[a];
  }
  return t;
}

// The bracket of E_q for one particle, 1/2 sum_ab N_ab e_a : C0 : e_b + sum_a mu_a (C0 : E) : e_a
// (times V_I in E_q), from its stresses t at (F, G).
template <int D>
double taylorTermEnergyDensity(const Vec<D>& offset, const Mat<D>& spread, bool small,
                               const Mat<D>& F, const std::array<Mat<D>, D>& G,
                               const TaylorStresses<D>& t) {
  double e = 0.0;
  for (int a = 0; a < D; ++a) {
    const Mat<D> A = small ? G[a] : Mat<D>(F.transpose() * G[a]);
    const Mat<D> ea = 0.5 * (A + A.transpose());  // e_a
    for (int b = 0; b < D; ++b)
      e += 0.5 * spread(a, b) * (t.s[b].array() * ea.array()).sum();
    e += offset[a] * (t.S.array() * ea.array()).sum();
  }
  return e;
}

// The linearisation of one particle's P^q and R_a (TaylorCorrection::stress and hyperstress)
// about (F, G) in a direction whose displacement gradient is dH and second gradients dG, given
// the particle's constants (mu, N, lambda, mu_lame, small: linear-elastic) and its sigma_a and
// tau at (F, G); the plain term and the fast pass (fast/TaylorQuadrature.hpp) both call it.
// With de_a = sym(dH^T G_a + F^T dG_a) and dE = sym(F^T dH) (sym(dG_a) and sym(dH) for the
// linear-elastic material),
//   dsigma_a = sum_b N_ab C0 : de_b + mu_a C0 : dE,   dtau = sum_a mu_a C0 : de_a,
//   dP^q = sum_a (dG_a sigma_a + G_a dsigma_a) + dH tau + F dtau,   dR_a = dH sigma_a + F
//   dsigma_a
// (dP^q = dtau and dR_a = dsigma_a for the linear-elastic material).
template <int D>
struct TaylorLinearised {
  Mat<D> stress;
  std::array<Mat<D>, D> hyperstress;
};
template <int D>
TaylorLinearised<D> linearisedTaylorTerm(const Vec<D>& offset, const Mat<D>& spread, double lambda,
                                         double mu, bool small, const Mat<D>& F,
                                         const std::array<Mat<D>, D>& G,
                                         const std::array<Mat<D>, D>& sigma, const Mat<D>& tau,
                                         const Mat<D>& dH, const std::array<Mat<D>, D>& dG) {
  auto C0 = [&](const Mat<D>& A) -> Mat<D> {  // C0 : sym(A)
    const Mat<D> e = 0.5 * (A + A.transpose());
    return lambda * e.trace() * Mat<D>::Identity() + 2.0 * mu * e;
  };
  std::array<Mat<D>, D> ds;  // C0 : de_a
  for (int a = 0; a < D; ++a)
    ds[a] = C0(small ? dG[a] : Mat<D>(dH.transpose() * G[a] + F.transpose() * dG[a]));
  const Mat<D> dS = C0(small ? dH : Mat<D>(F.transpose() * dH));  // C0 : dE
  Mat<D> dtau = Mat<D>::Zero();
  for (int a = 0; a < D; ++a)
    dtau += offset[a] * ds[a];
  TaylorLinearised<D> d;
  d.stress = small ? dtau : Mat<D>(dH * tau + F * dtau);
  for (int a = 0; a < D; ++a) {
    Mat<D> dsigma = offset[a] * dS;
    for (int b = 0; b < D; ++b)
      dsigma += spread(a, b) * ds[b];
    if (small) {
      d.hyperstress[a] = dsigma;
    } else {
      d.stress += dG[a] * sigma[a] + G[a] * dsigma;
      d.hyperstress[a] = dH * sigma[a] + F * dsigma;
    }
  }
  return d;
}

template <int D>
class TaylorCorrection {
 public:
  using Gradients = std::array<Mat<D>, D>;  // G_a = dF/dX_a, a = 0..D-1 (likewise R_a)

  // Fits the second-derivative vectors S_IJ (TaylorCorrection.cpp: the fit's moment matrices
  // are inverted there, compiled once; the fast pass's set-up calls the same functions).
  TaylorCorrection(const ReferenceConfiguration<D>& ref, const std::vector<Material>& materials,
                   const std::vector<std::uint16_t>& materialOf, const std::vector<double>& volume,
                   const std::vector<std::uint8_t>& passive = {},
                   const QuadratureMoments<D>& moments = {});

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

  // E_q for the F and G of every particle.
  double energy(const std::vector<Mat<D>>& F, const std::vector<Gradients>& G) const {
    double E = 0.0;
    for (Index i = 0; i < ref_.particleCount(); ++i)
      E += volume_[i] * taylorTermEnergyDensity<D>(offset_[i], spread_[i], smallStrain_[i], F[i],
                                                   G[i], stresses(i, F[i], G[i]));
    return E;
  }

  // sigma_a and tau (taylorTermStresses above).
  using Stresses = TaylorStresses<D>;
  Stresses stresses(Index i, const Mat<D>& F, const Gradients& G) const {
    return taylorTermStresses<D>(offset_[i], spread_[i], lambda_[i], mu_[i], smallStrain_[i], F, G);
  }

  // P^q_I = sum_a G_a sigma_a + F tau (tau for the linear-elastic material, whose e_a has no F).
  Mat<D> stress(Index i, const Mat<D>& F, const Gradients& G) const {
    const Stresses t = stresses(i, F, G);
    if (smallStrain_[i]) return t.tau;
    Mat<D> Pq = F * t.tau;
    for (int a = 0; a < D; ++a)
      Pq += G[a] * t.sigma[a];
    return Pq;
  }

  // R_Ia = F_I sigma_a (sigma_a for the linear-elastic material).
  Gradients hyperstress(Index i, const Mat<D>& F, const Gradients& G) const {
    const Stresses t = stresses(i, F, G);
    Gradients R;
    for (int a = 0; a < D; ++a)
      R[a] = smallStrain_[i] ? t.sigma[a] : Mat<D>(F * t.sigma[a]);
    return R;
  }

  // The linearisation of stress() and hyperstress() about (F, G) in a direction whose
  // displacement gradient is dH and second gradients dG (linearisedTaylorTerm above).
  using Linearised = TaylorLinearised<D>;
  Linearised linearised(Index i, const Mat<D>& F, const Gradients& G, const Mat<D>& dH,
                        const Gradients& dG) const {
    const Stresses t = stresses(i, F, G);
    return linearisedTaylorTerm<D>(offset_[i], spread_[i], lambda_[i], mu_[i], smallStrain_[i], F,
                                   G, t.sigma, t.tau, dH, dG);
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
  std::vector<Vec<D>> offset_;             // mu_I; 0 where there is no term
  std::vector<Mat<D>> spread_;             // N_I; 0 where there is no term
  std::vector<double> lambda_, mu_;        // C0
  std::vector<std::uint8_t> smallStrain_;  // linear-elastic material: e_a = sym(G_a)
};

extern template class TaylorCorrection<2>;
extern template class TaylorCorrection<3>;

}  // namespace tlsph
