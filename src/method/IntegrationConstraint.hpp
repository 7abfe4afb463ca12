// The integration constraint on the gradient vectors of a body with a known boundary (a mesh
// body), so that a uniform stress is in equilibrium with its own tractions at every particle:
// the linear patch test with loaded surfaces.
//
// For a uniform stress P, the internal force of the pair sum (InternalForce.hpp) is
//   f_I = -P d_I,   d_I = sum_K V_K g_KI - V_I sum_J g_IJ,
// the one-point quadrature of int grad psi_I dV over the body (psi_I the test function the
// gradient vectors imply); the Taylor term adds the pair vectors h_KJ = S_KJ mu_K to g
// (TaylorCorrection.hpp: at an affine field its hyperstress is mu_a C0 : E). The tractions a
// load puts on the particles are P a_I, a_I = int lambda_I n dA over the boundary. Equilibrium
// of the uniform stress at every particle is the divergence theorem for the discrete sums:
//   d_I = a_I   for every I   (0 inside the body).
// On a lattice it holds by symmetry away from the surface; on an unstructured particle set it
// does not, and the defect a_I - d_I acts as a spurious traction on every particle: at a
// pressure-loaded surface its strain is off by O(1), whatever the resolution.
//
// The correction: g_KJ + delta_KJ with the smallest delta in the norm
// sum_KJ |delta_KJ|^2 / w_KJ (w_KJ = V_J: the kernel's weights, which vanish at the support's
// edge, made the solve much slower to converge and gave no better results) that (i) keeps each F_K
// exact for the fields the fit is exact for (sum_J delta_KJ p_m(X_J - X_K) = 0 for the fit's
// monomials p_m: linear and quadratic, linear on the linear fallback), and (ii) meets the
// constraint d_I = a_I. With the W-orthogonal projector onto (i) per particle,
//   Pi_K = W_K - W_K P_K^T M_K^{-1} P_K W_K   (M_K = P_K W_K P_K^T, the fit's moment matrix),
// the minimiser is delta_K = Pi_K (A^T lambda)_K with (A^T lambda)_KJ = V_K (lambda_J - lambda_K),
// and lambda solves A Pi A^T lambda = a - d (one system per component, solved together by
// conjugate gradients preconditioned by the sparse Cholesky factor of the assembled matrix,
// shifted by 1e-9 of its diagonal; lambda polynomial up to the fit's order is its null space, and
// the defect's part along it is the O(h^2) quadrature error that no such delta can remove). F stays
// the gradient of the same displacement field to the fit's order and the internal force stays
// -dE/du (the corrected g are just other vectors), so momentum, objectivity and the symmetric
// tangent are kept.
//
// The linear-stress constraint (`integration_constraint = linear`) adds the first moments: for a
// stress varying linearly in X, equilibrium with its tractions and its divergence at every
// particle needs, besides d_I = a_I,
//   m_I = b_I - V_I 1,   m_I = sum_K V_K (X_K - X_I) (x) v_KI,
//   b_I = int lambda_I (X - X_I) (x) n dA   (geometry/BoundaryArea.hpp).
// Its correction is again delta_K = Pi_K (A^T mu)_K, now with
// (A^T mu)_KJ = V_K [(lambda_J - lambda_K) + Lambda_J^T (X_K - X_J)], 1 + D multipliers per
// particle and component. The operator B = A Pi A^T annihilates a cubic lambda paired with a
// quadratic Lambda (18 directions per component in 2D, 40 in 3D), and above them it has a
// continuum of small eigenvalues: smooth multiplier fields, whose pair differences are nearly
// the polynomials Pi removes. The first moments' defect along them is the nodal quadrature's
// smooth O(h^2) error, which no local correction should chase (enforcing it makes the
// corrections as large as the vectors and the solution worse), so that part of the constraint is
// filtered: Lambda's equations are shifted by `filter` times their diagonal (a Tikhonov penalty,
// in the dual, on the first moments' defect), while d_I = a_I is enforced. What no correction
// can change is left, as for the uniform constraint: the defects' part along B's null space
// (found as B's eigenvectors on that polynomial span), where the two defects are tied and
// their mismatch is the same O(h^2) quadrature error; so the uniform stress's balance is met
// to that (the tests: within 1e-2 of the uncorrected imbalance on coarse meshes, against 1e-3
// with the uniform constraint alone). Solved matrix-free by conjugate gradients on the null
// space's complement, preconditioned by the sparse Cholesky factor of lambda's block (the
// uniform constraint's matrix) and Lambda's diagonal blocks.
#pragma once

#include <vector>

#include "method/ReferenceConfiguration.hpp"
#include "model/QuadratureMoments.hpp"
#include "model/Types.hpp"

namespace tlsph {

// The default filter of the linear-stress constraint, relative to Lambda's diagonal.
constexpr double kLinearConstraintFilter = 1e-3;

// d_I = sum_K V_K v_KI - V_I sum_J v_IJ for the pair vectors v.
template <int D>
std::vector<Vec<D>> quadratureDefect(const NeighbourList& nb, const PairArray<Vec<D>>& v,
                                     const std::vector<double>& volume);

// h_KJ = S_KJ mu_K of the Taylor term (zero on the linear fallback and where mu = 0).
template <int D>
PairArray<Vec<D>> taylorPairVectors(const ReferenceConfiguration<D>& ref,
                                    const std::vector<double>& volume,
                                    const QuadratureMoments<D>& moments);

// Corrects ref's gradient vectors (and their sums and reverse vectors) so that d_I = a_I with
// the pair vectors g + extra (extra: the Taylor term's h, or empty), and records what it did in
// ref.integrationConstraint. boundaryArea: a_I per particle. Throws SetupError when the
// constraint cannot be met (the boundary is not closed).
template <int D>
void enforceIntegrationConstraint(ReferenceConfiguration<D>& ref, const std::vector<Vec<D>>& X,
                                  const std::vector<double>& volume,
                                  const std::vector<Vec<D>>& boundaryArea,
                                  const PairArray<Vec<D>>& extra);

// The same with the first moments too (the linear-stress constraint): boundaryMoment b_I per
// particle, filter > 0 the shift of Lambda's equations relative to their diagonal.
template <int D>
void enforceLinearStressConstraint(ReferenceConfiguration<D>& ref, const std::vector<Vec<D>>& X,
                                   const std::vector<double>& volume,
                                   const std::vector<Vec<D>>& boundaryArea,
                                   const std::vector<Mat<D>>& boundaryMoment, double filter,
                                   const PairArray<Vec<D>>& extra);

// A scene's reference configuration: the pair data, with the integration constraint where the
// scene knows its body's boundary (a mesh body; boundaryMoment non-empty: the linear-stress
// one, with its filter). rows: the pair data of these particles only (a distributed rank's),
// each exactly as in the whole build, whose correction is global.
template <int D>
ReferenceConfiguration<D> buildSceneReference(
    const std::vector<Vec<D>>& X, const std::vector<double>& volume, const Kernel<D>& kernel,
    const PeriodicBox<D>& box, GradientCorrection correction, Quadrature quadrature,
    const QuadratureMoments<D>& moments, const std::vector<Vec<D>>& boundaryArea,
    const std::vector<Mat<D>>& boundaryMoment, double filter,
    const std::vector<Index>* rows = nullptr);

}  // namespace tlsph
