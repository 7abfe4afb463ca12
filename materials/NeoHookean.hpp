// Compressible neo-Hookean solid.
#pragma once

#include <Eigen/Core>
#include <cmath>

#include "materials/ModelParameters.hpp"
#include "materials/Tensor.hpp"

namespace tlsph {

// psi = mu/2 (I1 - 3) - mu ln J + lambda/2 (ln J)^2,  I1 = tr(F^T F), J = det F.
// With dI1/dF = 2F and dJ/dF = J F^{-T}:  P = mu (F - F^{-T}) + lambda ln J F^{-T}.
// At F = 1 both terms vanish and the linearisation is sigma(eps) with the same lambda, mu.
// psi -> infinity as J -> 0+, which resists inversion.
// Tangent (d F^{-T} = -F^{-T} dF^T F^{-T}, d ln J = F^{-T}:dF):
//   dP = mu dF + (mu - lambda ln J) F^{-T} dF^T F^{-T} + lambda (F^{-T}:dF) F^{-T}.
//
// For J <= 0 (an inverted or collapsed particle) the model is undefined: energy and stress
// are quiet NaN. This does not throw, on purpose: it happens inside the parallel stress
// loop, and the solver's finiteness guard reports the run as unstable.
class NeoHookean : public ModelParameters {
 public:
  static constexpr const char* name = "neo-hookean";
  static constexpr bool objective = true;

  NeoHookean(const ElasticConstants& c, double density) : ModelParameters(c, density) {}

  double strainEnergyDensity(const Eigen::Matrix3d& F) const {
    const double J = F.determinant();
    if (!(J > 0.0)) return tensor::undefinedEnergy();
    const double lnJ = std::log(J);
    const double mu = constants().mu;
    return 0.5 * mu * (F.squaredNorm() - 3.0) - mu * lnJ + 0.5 * constants().lambda * lnJ * lnJ;
  }

  Eigen::Matrix3d firstPiolaKirchhoff(const Eigen::Matrix3d& F) const {
    const Eigen::Matrix3d cof = tensor::cofactor(F);  // J F^{-T}
    const double J = tensor::determinantFromCofactor(F, cof);
    if (!(J > 0.0)) return tensor::undefinedStress();
    const double mu = constants().mu;
    // P = mu F + (lambda ln J - mu) F^{-T}
    return mu * F + ((constants().lambda * std::log(J) - mu) / J) * cof;
  }

  // A = dP/dF (A(i+3j, k+3l) = dP_ij/dF_kl, see Material.hpp); formula above.
  Eigen::Matrix<double, 9, 9> tangentModulus(const Eigen::Matrix3d& F) const {
    const Eigen::Matrix3d cof = tensor::cofactor(F);
    const double J = tensor::determinantFromCofactor(F, cof);
    if (!(J > 0.0)) return tensor::undefinedTangent();
    const double lambda = constants().lambda;
    const double mu = constants().mu;
    const Eigen::Matrix3d H = cof / J;  // F^{-T}
    const tensor::Vector9d h = tensor::vec(H);
    tensor::Tangent A = lambda * h * h.transpose();
    A.diagonal().array() += mu;
    tensor::addLeftTransposedRight(A, mu - lambda * std::log(J), H, H);
    return A;
  }
};

}  // namespace tlsph
