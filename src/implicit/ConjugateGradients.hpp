// Preconditioned conjugate gradients for a symmetric positive definite operator given as a
// product (the matrix-free tangent stiffness), with a symmetric positive definite
// preconditioner (a sparse Cholesky factor). Shared by the Newton solver and the modal analysis.
#pragma once

#include <Eigen/Core>
#include <algorithm>

namespace tlsph {

struct ConjugateGradientResult {
  int iterations = 0;
  double residual = 0.0;           // |b - A x| at the end
  bool negativeCurvature = false;  // p^T A p < 0 met: A is not positive definite
};

// Improves x (the initial guess) towards A x = b until |b - A x| <= target, maxIterations, a
// direction of non-positive curvature, or a stall: near round-off the residual stops falling,
// so the iteration ends when it has not halved over `stall` iterations.
// apply(v, Av) and precondition(r) -> z = M^{-1} r.
template <class Apply, class Precondition>
ConjugateGradientResult conjugateGradients(Apply&& apply, Precondition&& precondition,
                                           const Eigen::VectorXd& b, Eigen::VectorXd& x,
                                           double target, int maxIterations, int stall = 20) {
  ConjugateGradientResult result;
  Eigen::VectorXd Ap(b.size());
  apply(x, Ap);
  Eigen::VectorXd r = b - Ap;
  Eigen::VectorXd z = precondition(r);
  Eigen::VectorXd p = z;
  double rz = r.dot(z);
  double earlier = r.norm();
  double scale = 0.0;  // largest p^T A p / p^T p so far
  for (; result.iterations < maxIterations && r.norm() > target; ++result.iterations) {
    if (result.iterations > 0 && result.iterations % stall == 0) {
      if (r.norm() > 0.5 * earlier) break;
      earlier = r.norm();
    }
    apply(p, Ap);
    // p^T A p against the largest Rayleigh quotient seen: clearly negative means A is not
    // positive definite; within round-off of zero (p itself at round-off) means done.
    const double curvature = p.dot(Ap), pp = p.squaredNorm();
    if (curvature > 0.0) scale = std::max(scale, curvature / pp);
    if (!(curvature > 1e-13 * scale * pp)) {
      result.negativeCurvature = !(curvature > -1e-8 * scale * pp);
      break;
    }
    const double a = rz / curvature;
    x += a * p;
    r -= a * Ap;
    z = precondition(r);
    const double rzNew = r.dot(z);
    p = z + (rzNew / rz) * p;
    rz = rzNew;
  }
  result.residual = r.norm();
  return result;
}

}  // namespace tlsph
