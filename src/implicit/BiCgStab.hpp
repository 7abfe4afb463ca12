// Preconditioned BiCGSTAB (van der Vorst) for a non-symmetric operator given as a product: the
// Newton tangent of a scene with a following pressure, whose load stiffness is not symmetric,
// preconditioned by the factor or the multigrid of the symmetric strain part.
#pragma once

#include <Eigen/Core>
#include <cmath>

namespace tlsph {

struct BiCgStabResult {
  int iterations = 0;
  double residual = 0.0;   // |b - A x| at the end
  bool breakdown = false;  // rho or omega vanished before the target was reached
};

// Improves x (the initial guess) towards A x = b until |b - A x| <= target, maxIterations, a
// breakdown, or a stall (the residual has not halved over `stall` iterations, as near
// round-off). apply(v, Av) and precondition(r) -> z = M^{-1} r; each iteration applies both
// twice.
template <class Apply, class Precondition>
BiCgStabResult biCgStab(Apply&& apply, Precondition&& precondition, const Eigen::VectorXd& b,
                        Eigen::VectorXd& x, double target, int maxIterations, int stall = 20) {
  BiCgStabResult result;
  const Eigen::Index n = b.size();
  Eigen::VectorXd v = Eigen::VectorXd::Zero(n), p = Eigen::VectorXd::Zero(n), t(n);
  apply(x, t);
  Eigen::VectorXd r = b - t;
  const Eigen::VectorXd shadow = r;
  double rho = 1.0, alpha = 1.0, omega = 1.0;
  double earlier = r.norm();
  for (; result.iterations < maxIterations && r.norm() > target; ++result.iterations) {
    if (result.iterations > 0 && result.iterations % stall == 0) {
      if (r.norm() > 0.5 * earlier) break;
      earlier = r.norm();
    }
    const double rhoNew = shadow.dot(r);
    if (rhoNew == 0.0 || omega == 0.0 || !std::isfinite(rhoNew)) {
      result.breakdown = true;
      break;
    }
    p = r + (rhoNew / rho) * (alpha / omega) * (p - omega * v);
    const Eigen::VectorXd pHat = precondition(p);
    apply(pHat, v);
    const double sv = shadow.dot(v);
    if (sv == 0.0) {
      result.breakdown = true;
      break;
    }
    alpha = rhoNew / sv;
    x += alpha * pHat;
    r -= alpha * v;
    rho = rhoNew;
    if (r.norm() <= target) {
      ++result.iterations;
      break;
    }
    const Eigen::VectorXd sHat = precondition(r);
    apply(sHat, t);
    const double tt = t.squaredNorm();
    omega = tt > 0.0 ? t.dot(r) / tt : 0.0;
    x += omega * sHat;
    r -= omega * t;
  }
  result.residual = r.norm();
  return result;
}

}  // namespace tlsph
