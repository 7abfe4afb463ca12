// The rigid motions of a body that nothing holds, for a static solve of a free body under loads
// that balance (a ring under internal pressure, say). Its tangent stiffness K is singular: the
// rigid motions (D translations, and 1 rotation in 2D, 3 in 3D) cost no energy. The Newton
// solver keeps every correction orthogonal to them, v -> (1 - Q Q^T) v with Q an orthonormal
// basis of the rigid motions of the unknowns at the present positions, so the conjugate
// gradients work on K restricted to the deformations, where it is positive definite, and the
// displacement found has no mean translation or rotation. The preconditioner's matrix is made
// definite by a small shift of its diagonal (shiftDiagonal), harmless because its result is
// projected as well.
#pragma once

#include <Eigen/Core>
#include <Eigen/QR>
#include <Eigen/SparseCore>
#include <vector>

#include "model/Scene.hpp"
#include "model/Types.hpp"

namespace tlsph {

// True when nothing holds the scene's bodies: no clamp, ghost or prescribed particle.
template <int D>
bool heldByNothing(const Scene<D>& scene) {
  if (!scene.mirrorGhosts.empty() || !scene.prescriptions.empty()) return false;
  for (Motion m : scene.particles.motion)
    if (m != Motion::Free) return false;
  return true;
}

template <int D>
class RigidModes {
 public:
  static constexpr int kCount = D == 2 ? 3 : 6;

  // The basis for the particles `free` (the unknowns, D per particle, stacked) at x = X + u;
  // rotations about their centroid.
  void update(const std::vector<Index>& free, const std::vector<Vec<D>>& X,
              const std::vector<Vec<D>>& u) {
    const Index n = static_cast<Index>(free.size());
    Vec<D> centre = Vec<D>::Zero();
    for (Index i : free)
      centre += X[i] + u[i];
    centre /= std::max<double>(1.0, static_cast<double>(n));
    Eigen::MatrixXd modes = Eigen::MatrixXd::Zero(D * n, kCount);
    for (Index k = 0; k < n; ++k) {
      const Vec<D> r = X[free[k]] + u[free[k]] - centre;
      for (int a = 0; a < D; ++a)
        modes(D * k + a, a) = 1.0;
      if constexpr (D == 2) {
        modes(D * k, 2) = -r.y();
        modes(D * k + 1, 2) = r.x();
      } else {
        for (int axis = 0; axis < 3; ++axis) {
          const Vec<3> w = Vec<3>::Unit(axis).cross(r);
          modes.block<3, 1>(D * k, 3 + axis) = w;
        }
      }
    }
    const Eigen::HouseholderQR<Eigen::MatrixXd> qr(modes);
    basis_ = qr.householderQ() * Eigen::MatrixXd::Identity(D * n, kCount);
  }

  // v -> v minus its rigid part.
  void project(Eigen::VectorXd& v) const { v -= basis_ * (basis_.transpose() * v); }

  // The rigid part's norm, |Q^T v|.
  double rigidPart(const Eigen::VectorXd& v) const { return (basis_.transpose() * v).norm(); }

 private:
  Eigen::MatrixXd basis_;  // D n x kCount, orthonormal columns
};

// The lower triangle `lower` with its diagonal raised by the fraction kRigidShift: the rigid
// motions' zero eigenvalues become kRigidShift times the diagonal's, so the factorisation of a
// free body's K succeeds; the deformations' eigenvalues (at least about (dx / L)^2 of the
// diagonal) barely move, so the factor still preconditions them well.
inline constexpr double kRigidShift = 1e-8;

template <class Matrix>
Matrix shiftDiagonal(const Matrix& lower) {
  Matrix shifted = lower;
  for (Eigen::Index i = 0; i < shifted.rows(); ++i)
    shifted.coeffRef(i, i) *= 1.0 + kRigidShift;
  return shifted;
}

}  // namespace tlsph
