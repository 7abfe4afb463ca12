// Compressible Mooney-Rivlin solid (isochoric invariants plus a volumetric penalty).
#pragma once

#include <Eigen/Core>
#include <cmath>

#include "materials/ModelParameters.hpp"
#include "materials/Tensor.hpp"

namespace tlsph {

// psi = c10 (Ibar1 - 3) + c01 (Ibar2 - 3) + K/2 (J - 1)^2, with C = F^T F,
// I1 = tr C, I2 = ((tr C)^2 - tr(C^2))/2, Ibar1 = J^{-2/3} I1, Ibar2 = J^{-4/3} I2.
// The isochoric invariants make the split exact: the first two terms resist only shape
// change, the last only volume change. Linearised at F = 1 the shear modulus is
// 2 (c10 + c01) and the bulk modulus K, so the model takes c10 + c01 = mu/2 from the given
// constants and splits it by c01Fraction (0: neo-Hookean-like, 1: pure c01 term).
//
// For J <= 0 energy and stress are quiet NaN (not an exception; see NeoHookean.hpp).
class MooneyRivlin : public ModelParameters {
 public:
  static constexpr const char* name = "mooney-rivlin";
  static constexpr bool objective = true;

  // Throws MaterialError unless c01Fraction is in [0, 1] (and the density is valid).
  MooneyRivlin(const ElasticConstants& c, double density, double c01Fraction = 0.5)
      : ModelParameters(c, density) {
    if (!(c01Fraction >= 0.0 && c01Fraction <= 1.0))
      throw MaterialError("Mooney-Rivlin c01Fraction = " + detail::formatNumber(c01Fraction) +
                          " is outside the allowed range [0, 1] (c01 = c01Fraction * mu/2, "
                          "c10 = mu/2 - c01)");
    c01_ = c01Fraction * 0.5 * c.mu;
    c10_ = 0.5 * c.mu - c01_;
  }

  double c10() const { return c10_; }
  double c01() const { return c01_; }

  double strainEnergyDensity(const Eigen::Matrix3d& F) const {
    const double J = F.determinant();
    if (!(J > 0.0)) return tensor::undefinedEnergy();
    const Eigen::Matrix3d C = F.transpose() * F;
    const double I1 = C.trace();
    const double I2 = 0.5 * (I1 * I1 - C.squaredNorm());  // C symmetric: tr(C^2) = C:C
    const double Jm23 = 1.0 / (std::cbrt(J) * std::cbrt(J));
    const double dJ = J - 1.0;
    return c10_ * (Jm23 * I1 - 3.0) + c01_ * (Jm23 * Jm23 * I2 - 3.0) +
           0.5 * constants().bulkModulus * dJ * dJ;
  }

  // P = c10 dIbar1/dF + c01 dIbar2/dF + K (J - 1) J F^{-T}, where (dJ/dF = J F^{-T})
  //   dIbar1/dF = J^{-2/3} (2 F - 2/3 I1 F^{-T}),
  //   dIbar2/dF = J^{-4/3} (2 I1 F - 2 F C - 4/3 I2 F^{-T})   (dI2/dF = 2 F (I1 1 - C)).
  Eigen::Matrix3d firstPiolaKirchhoff(const Eigen::Matrix3d& F) const {
    const Eigen::Matrix3d cof = tensor::cofactor(F);  // J F^{-T}
    const double J = tensor::determinantFromCofactor(F, cof);
    if (!(J > 0.0)) return tensor::undefinedStress();
    const Eigen::Matrix3d C = F.transpose() * F;
    const double I1 = C.trace();
    const double I2 = 0.5 * (I1 * I1 - C.squaredNorm());
    const double cbrtJ = std::cbrt(J);
    const double Jm23 = 1.0 / (cbrtJ * cbrtJ);
    const double Jm43 = Jm23 * Jm23;
    const double a = 2.0 * c10_ * Jm23;  // coefficient of F from Ibar1
    const double b = 2.0 * c01_ * Jm43;  // coefficient of (I1 F - F C) from Ibar2
    // All F^{-T} = cof / J terms collected into one coefficient of cof.
    const double g = (-a * I1 / 3.0 - 2.0 * b * I2 / 3.0) / J + constants().bulkModulus * (J - 1.0);
    Eigen::Matrix3d P = (a + b * I1) * F;
    P.noalias() -= b * (F * C);
    P += g * cof;
    return P;
  }

  // A = dP/dF (A(i+3j, k+3l) = dP_ij/dF_kl, see Material.hpp). With H = F^{-T},
  // N = I1 F - F C (dI2 = 2 N:dF) and the coefficients of firstPiolaKirchhoff,
  //   P = (a + b I1) F - b F C + h H,   h = J g = -a I1/3 - 2 b I2/3 + K J (J - 1),
  // and da = -2/3 a (H:dF), db = -4/3 b (H:dF), dI1 = 2 F:dF, dJ = J H:dF, dH = -H dF^T H,
  // d(F C) = dF C + F dF^T F + F F^T dF, term by term:
  //   dP = (a + b I1) dF - b (dF C + F dF^T F + F F^T dF) - h H dF^T H
  //      + 2 b (F:dF) F - 2/3 a [(H:dF) F + (F:dF) H] - 4/3 b [(H:dF) N + (N:dF) H]
  //      + (2/9 a I1 + 8/9 b I2 + K J (2 J - 1)) (H:dF) H.
  Eigen::Matrix<double, 9, 9> tangentModulus(const Eigen::Matrix3d& F) const {
    const Eigen::Matrix3d cof = tensor::cofactor(F);
    const double J = tensor::determinantFromCofactor(F, cof);
    if (!(J > 0.0)) return tensor::undefinedTangent();
    const Eigen::Matrix3d C = F.transpose() * F;
    const double I1 = C.trace();
    const double I2 = 0.5 * (I1 * I1 - C.squaredNorm());
    const double cbrtJ = std::cbrt(J);
    const double Jm23 = 1.0 / (cbrtJ * cbrtJ);
    const double a = 2.0 * c10_ * Jm23;
    const double b = 2.0 * c01_ * Jm23 * Jm23;
    const double K = constants().bulkModulus;
    const double h = -a * I1 / 3.0 - 2.0 * b * I2 / 3.0 + K * J * (J - 1.0);
    const Eigen::Matrix3d H = cof / J;
    const Eigen::Matrix3d FC = F * C;
    const tensor::Vector9d f = tensor::vec(F);
    const tensor::Vector9d hv = tensor::vec(H);
    const tensor::Vector9d n = tensor::vec(I1 * F - FC);
    const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();

    tensor::Tangent A = (2.0 * b) * f * f.transpose();
    A.noalias() -= (2.0 / 3.0 * a) * (f * hv.transpose() + hv * f.transpose());
    A.noalias() -= (4.0 / 3.0 * b) * (n * hv.transpose() + hv * n.transpose());
    A.noalias() +=
        (2.0 / 9.0 * a * I1 + 8.0 / 9.0 * b * I2 + K * J * (2.0 * J - 1.0)) * hv * hv.transpose();
    A.diagonal().array() += a + b * I1;
    tensor::addLeftRight(A, -b, I, C);
    tensor::addLeftRight(A, -b, F * F.transpose(), I);
    tensor::addLeftTransposedRight(A, -b, F, F);
    tensor::addLeftTransposedRight(A, -h, H, H);
    return A;
  }

 private:
  double c10_;
  double c01_;
};

}  // namespace tlsph
