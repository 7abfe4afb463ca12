// The stress at a particle on a loaded or free surface, recovered from the surface's own data
// (docs/method.md section 3.5).
//
// A particle's own F is least accurate at a one-sided surface: its fit sees neighbours on one
// side only, and any surface noise of the solved field goes straight into its normal
// derivative. On a surface two things are known better: the displacements of the surface
// particles beside it, which give the gradient's tangential part, and the traction the
// conditions put there, which fixes the normal part. With N the outward unit normal and T an
// orthonormal basis of the tangent plane (T T^T + N N^T = 1),
//   Grad u = B T^T + g N^T,
//   B = du/dxi at xi = 0, from a weighted quadratic least-squares fit of the surface particles'
//       displacements over the tangent-plane coordinates xi_J = T^T (X_J - X_I), each first
//       carried back to the tangent plane, u_J - g zeta_J with zeta_J = N . (X_J - X_I) (on a
//       curved surface zeta is not a quadratic in xi, and the rest would leak into B),
//   g from the traction condition  P(1 + Grad u) N = t0  (D equations, D unknowns),
// t0 the applied traction per unit reference area (a following pressure p: t0 = -p cof(F) N).
// The traction condition is solved by Newton's method with the material's tangent
// dP/dF: its Jacobian is the acoustic tensor A_iKjL N_K N_L, invertible wherever the material is
// strongly elliptic. The recovery is exact for affine displacements with their own traction
// (the fit reproduces quadratics in xi) and second order in the particle spacing otherwise.
#pragma once

#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "materials/Material.hpp"
#include "model/Types.hpp"

namespace tlsph {

template <int D>
using TangentBasis = Eigen::Matrix<double, D, D - 1>;

// The fit at one surface particle: B = sum_J u_J s_J^T.
template <int D>
struct SurfaceStencil {
  Index particle = -1;
  Vec<D> normal = Vec<D>::Zero();  // N, outward, unit
  TangentBasis<D> tangents;        // T
  std::vector<Index> neighbours;   // the surface particles of the fit (I among them)
  std::vector<Vec<D - 1>> slope;   // s_J, one per neighbour
  std::vector<double> offset;      // zeta_J = N . (X_J - X_I), one per neighbour
};

// An orthonormal basis of the plane normal to the unit vector n.
template <int D>
TangentBasis<D> tangentBasis(const Vec<D>& n) {
  TangentBasis<D> t;
  if constexpr (D == 2) {
    t.col(0) = Vec<2>(-n.y(), n.x());
  } else {
    Vec<3> axis = Vec<3>::Zero();
    int least = 0;
    n.cwiseAbs().minCoeff(&least);
    axis[least] = 1.0;
    t.col(0) = axis.cross(n).normalized();
    t.col(1) = n.cross(t.col(0));
  }
  return t;
}

// The quadratic monomials in xi (scaled by the radius): 1, xi, xi^2 in 2D; 1, xi1, xi2, xi1^2,
// xi1 xi2, xi2^2 in 3D.
template <int D>
Eigen::Matrix<double, D == 2 ? 3 : 6, 1> tangentPlaneBasis(const Vec<D - 1>& xi) {
  if constexpr (D == 2)
    return {1.0, xi[0], xi[0] * xi[0]};
  else
    return (Eigen::Matrix<double, 6, 1>() << 1.0, xi[0], xi[1], xi[0] * xi[0], xi[0] * xi[1],
            xi[1] * xi[1])
        .finished();
}

// The fit at surface particle i: `areaVector` its int lambda_I n dA (any positive multiple of
// the normal), `candidates` the particles of its surface, with their area vectors, the fit
// taking those within `radius` whose normal is within 60 degrees of i's (so that a named
// surface with an edge is not fitted across it). The weights are the kernel's shape,
// (1 - r/R)^4 (1 + 4 r/R). Empty optional, with `why` set, when the fit is not determined (too
// few particles, or all on one line).
template <int D>
std::optional<SurfaceStencil<D>> surfaceStencil(Index i, const std::vector<Vec<D>>& X,
                                                const std::vector<Index>& candidates,
                                                const std::vector<Vec<D>>& areaVector,
                                                const Vec<D>& ownAreaVector, double radius,
                                                std::string& why) {
  constexpr int m = D == 2 ? 3 : 6;
  SurfaceStencil<D> s;
  s.particle = i;
  s.normal = ownAreaVector.normalized();
  s.tangents = tangentBasis<D>(s.normal);
  std::vector<Vec<D - 1>> xi;
  std::vector<double> w;
  for (std::size_t k = 0; k < candidates.size(); ++k) {
    const Vec<D> d = X[candidates[k]] - X[i];
    const double r = d.norm() / radius;
    if (r >= 1.0 || areaVector[k].normalized().dot(s.normal) < 0.5) continue;
    s.neighbours.push_back(candidates[k]);
    s.offset.push_back(s.normal.dot(d));
    xi.push_back(s.tangents.transpose() * d / radius);
    const double q = 1.0 - r;
    w.push_back(q * q * q * q * (1.0 + 4.0 * r));
  }
  const int n = static_cast<int>(s.neighbours.size());
  Eigen::MatrixXd A(n, m);
  for (int k = 0; k < n; ++k)
    A.row(k) = std::sqrt(w[k]) * tangentPlaneBasis<D>(xi[k]).transpose();
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(A);
  if (n < m || qr.rank() < m) {
    why = std::to_string(n) + " surface particle(s) within " + std::to_string(radius) +
          " m, which do not determine a quadratic fit of " + std::to_string(m) + " coefficients";
    return std::nullopt;
  }
  // The coefficients are qr.solve(sqrt(w) u); the linear ones, over the radius, are dU/dxi.
  const Eigen::MatrixXd sqrtW = Eigen::VectorXd::Map(w.data(), n).cwiseSqrt().asDiagonal();
  const Eigen::MatrixXd coefficients = qr.solve(sqrtW);  // m x n
  for (int k = 0; k < n; ++k)
    s.slope.push_back(coefficients.block(1, k, D - 1, 1) / radius);
  return s;
}

// The displacement gradient at the stencil's particle: tangential part from the fit,
// normal part from P(1 + Grad u) N = t0, t0 = deadTraction - followingPressure cof(F) N. B
// depends on g through the offsets, weakly (zeta_J is of order h^2 / curvature radius): each
// Newton step on g refits B with the present g.
// `start` is a first guess of Grad u (the particle's own). NaN when Newton's method does not
// converge (a material that is not strongly elliptic there, or inverted).
template <int D>
Mat<D> recoveredDisplacementGradient(const SurfaceStencil<D>& s, const std::vector<Vec<D>>& u,
                                     const Material& material, const Vec<D>& deadTraction,
                                     double followingPressure, const Mat<D>& start) {
  const Vec<D>& N = s.normal;
  Vec<D> g = start * N;
  TangentBasis<D> B;
  for (int iteration = 0; iteration < 50; ++iteration) {
    B.setZero();
    for (std::size_t k = 0; k < s.neighbours.size(); ++k)
      B += (u[s.neighbours[k]] - s.offset[k] * g) * s.slope[k].transpose();
    const Mat<D> F = Mat<D>::Identity() + B * s.tangents.transpose() + g * N.transpose();
    Vec<D> t0 = deadTraction;
    // cof(F) = J F^-T (in plane strain the in-plane block: F_33 = 1).
    if (followingPressure != 0.0)
      t0 -= followingPressure * F.determinant() * F.inverse().transpose() * N;
    const Vec<D> r = firstPiolaKirchhoff<D>(material, F) * N - t0;
    const auto A = tangentModulus<D>(material, F);
    // d(P N)_i / d g_j = sum_KL A(i + D K, j + D L) N_K N_L, since dF = dg N^T. The following
    // pressure's own derivative is left out: a fixed point on it, converging at the rate p / E.
    Mat<D> acoustic = Mat<D>::Zero();
    for (int i = 0; i < D; ++i)
      for (int j = 0; j < D; ++j)
        for (int K = 0; K < D; ++K)
          for (int L = 0; L < D; ++L)
            acoustic(i, j) += A(i + D * K, j + D * L) * N[K] * N[L];
    const Vec<D> step = acoustic.partialPivLu().solve(r);
    if (!step.allFinite()) break;
    g -= step;
    if (step.norm() <= 1e-13 * (1.0 + g.norm()) + 1e-300)
      return B * s.tangents.transpose() + g * N.transpose();
  }
  return Mat<D>::Constant(std::numeric_limits<double>::quiet_NaN());
}

}  // namespace tlsph
