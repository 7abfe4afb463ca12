// Small-strain linear elasticity: eps = sym(F - 1), P = sigma(eps).
#pragma once

#include <Eigen/Core>

#include "materials/ModelParameters.hpp"
#include "materials/Tensor.hpp"

namespace tlsph {

// Uses the small-strain tensor as if it were a finite-strain measure, so it is NOT
// objective: a finite rigid rotation Q gives sym(Q - 1) != 0 and hence non-zero stress
// (for a rotation by theta about z, eps = (cos theta - 1) diag(1, 1, 0)). Valid only for
// small displacements *and* small rotations; use it as the reference model of linear
// benchmarks, not for large motion.
class LinearElastic : public ModelParameters {
 public:
  static constexpr const char* name = "linear-elastic";
  static constexpr bool objective = false;

  LinearElastic(const ElasticConstants& c, double density) : ModelParameters(c, density) {}

  // psi = lambda/2 tr(eps)^2 + mu eps:eps
  double strainEnergyDensity(const Eigen::Matrix3d& F) const {
    const Eigen::Matrix3d eps = strain(F);
    const double tr = eps.trace();
    return 0.5 * constants().lambda * tr * tr + constants().mu * eps.squaredNorm();
  }

  // dpsi/dF = sigma: psi depends on F only through sym(F), and sigma is symmetric.
  Eigen::Matrix3d firstPiolaKirchhoff(const Eigen::Matrix3d& F) const {
    const Eigen::Matrix3d eps = strain(F);
    Eigen::Matrix3d sigma = 2.0 * constants().mu * eps;
    sigma.diagonal().array() += constants().lambda * eps.trace();
    return sigma;
  }

  // A = dP/dF (A(i+3j, k+3l) = dP_ij/dF_kl, see Material.hpp). P is linear in F:
  // dP = lambda tr(dF) 1 + mu (dF + dF^T), so A = lambda vec(1) vec(1)^T + mu (Id + T) with
  // T the transpose map, for every F.
  Eigen::Matrix<double, 9, 9> tangentModulus(const Eigen::Matrix3d& /*F*/) const {
    const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
    const tensor::Vector9d one = tensor::vec(I);
    const double mu = constants().mu;
    tensor::Tangent A = constants().lambda * one * one.transpose();
    tensor::addLeftRight(A, mu, I, I);            // mu dF
    tensor::addLeftTransposedRight(A, mu, I, I);  // mu dF^T
    return A;
  }

 private:
  static Eigen::Matrix3d strain(const Eigen::Matrix3d& F) {
    Eigen::Matrix3d eps = 0.5 * (F + F.transpose());
    eps.diagonal().array() -= 1.0;
    return eps;
  }
};

}  // namespace tlsph
