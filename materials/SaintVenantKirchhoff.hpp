// Saint Venant-Kirchhoff: linear elasticity in the Green-Lagrange strain.
#pragma once

#include <Eigen/Core>

#include "materials/ModelParameters.hpp"
#include "materials/Tensor.hpp"

namespace tlsph {

// psi = lambda/2 tr(E)^2 + mu E:E with E = (F^T F - 1)/2: objective because E is, exact
// linear elasticity for small strain, but it softens and loses stability in strong
// compression (psi stays finite as det F -> 0), so use it for moderate strains.
class SaintVenantKirchhoff : public ModelParameters {
 public:
  static constexpr const char* name = "saint-venant-kirchhoff";
  static constexpr bool objective = true;

  SaintVenantKirchhoff(const ElasticConstants& c, double density) : ModelParameters(c, density) {}

  double strainEnergyDensity(const Eigen::Matrix3d& F) const {
    const Eigen::Matrix3d E = greenLagrange(F);
    const double tr = E.trace();
    return 0.5 * constants().lambda * tr * tr + constants().mu * E.squaredNorm();
  }

  // P = F S with the second Piola-Kirchhoff stress S = dpsi/dE = lambda tr(E) 1 + 2 mu E
  // (dE = sym(F^T dF), S symmetric).
  Eigen::Matrix3d firstPiolaKirchhoff(const Eigen::Matrix3d& F) const {
    const Eigen::Matrix3d E = greenLagrange(F);
    Eigen::Matrix3d S = 2.0 * constants().mu * E;
    S.diagonal().array() += constants().lambda * E.trace();
    return F * S;
  }

  // A = dP/dF (A(i+3j, k+3l) = dP_ij/dF_kl, see Material.hpp). dP = dF S + F dS with
  // dS = lambda tr(dE) 1 + 2 mu dE, dE = sym(F^T dF), tr(dE) = F:dF:
  //   dP = dF S + lambda (F:dF) F + mu (F F^T dF + F dF^T F).
  Eigen::Matrix<double, 9, 9> tangentModulus(const Eigen::Matrix3d& F) const {
    const double lambda = constants().lambda;
    const double mu = constants().mu;
    const Eigen::Matrix3d E = greenLagrange(F);
    Eigen::Matrix3d S = 2.0 * mu * E;
    S.diagonal().array() += lambda * E.trace();
    const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
    const tensor::Vector9d f = tensor::vec(F);
    tensor::Tangent A = lambda * f * f.transpose();
    tensor::addLeftRight(A, 1.0, I, S);
    tensor::addLeftRight(A, mu, F * F.transpose(), I);
    tensor::addLeftTransposedRight(A, mu, F, F);
    return A;
  }

 private:
  static Eigen::Matrix3d greenLagrange(const Eigen::Matrix3d& F) {
    Eigen::Matrix3d E = 0.5 * (F.transpose() * F);
    E.diagonal().array() -= 0.5;
    return E;
  }
};

}  // namespace tlsph
