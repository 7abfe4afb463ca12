// The per-step pair loops of total-Lagrangian SPH, read against DESIGN.md section 2:
//   displacements u -> deformation gradients F (6.69) -> stresses P
//   -> internal force (6.70) + Ganzenmueller hourglass force (6.80, 6.81).
// The corrected gradient vectors g_IJ (ReferenceConfiguration) carry L^{-1}: with them
// F_I = 1 + sum_J (u_J - u_I) (x) g_IJ and f_I = -dE/du_I = V_I (P_I G_I - sum_J P_J t_IJ),
// which for the linear correction is (6.70): V_I sum_J V_J (B_I + B_J) gradW_IJ, B = P L^{-T}.
// Everything that depends only on the reference configuration is precomputed, so the
// loops carry no branch on options: the hourglass term is a template parameter.
#pragma once

#include <cstdint>
#include <variant>
#include <vector>

#include "materials/Material.hpp"
#include "tlsph/ReferenceConfiguration.hpp"
#include "tlsph/Types.hpp"

namespace tlsph {

template <int D>
class TlsphForces {
 public:
  // hourglassCoefficient is alpha of (6.80), dimensionless; 0 switches the term off entirely.
  TlsphForces(const ReferenceConfiguration<D>& reference, const std::vector<Material>& materials,
              const std::vector<std::uint16_t>& materialOfParticle,
              const std::vector<double>& volume, double hourglassCoefficient)
      : ref_(reference),
        materials_(materials),
        materialOfParticle_(materialOfParticle),
        volume_(volume),
        alpha_(hourglassCoefficient),
        F_(reference.particleCount(), Mat<D>::Identity()),
        P_(reference.particleCount(), Mat<D>::Zero()) {
    const Index n = reference.particleCount();
    particlesOfMaterial_.resize(materials.size());
    for (Index i = 0; i < n; ++i)
      particlesOfMaterial_.at(materialOfParticle[i]).push_back(i);
    separateHourglassGradient_ = alpha_ != 0.0 && !reference.linearGradient.empty();
    if (separateHourglassGradient_) hourglassF_.assign(n, Mat<D>::Identity());
    if (alpha_ != 0.0) {
      // c_IJ = alpha (E_I + E_J)/2 V_J W_IJ / |X_IJ|^2: symmetric in I, J, so the pair
      // forces stay antisymmetric across material interfaces.
      hourglassForce_.assign(n, Vec<D>::Zero());
      hourglassStiffness_.resize(reference.neighbours.pairCount());
      const auto& nb = reference.neighbours;
      for (Index i = 0; i < n; ++i) {
        const double Ei = elasticConstants(materials[materialOfParticle[i]]).youngsModulus;
        for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k) {
          const Index j = nb.neighbour[k];
          const double Ej = elasticConstants(materials[materialOfParticle[j]]).youngsModulus;
          hourglassStiffness_[k] = alpha_ * 0.5 * (Ei + Ej) * volume[j] * reference.kernelValue[k] /
                                   reference.separation[k].squaredNorm();
        }
      }
    }
  }

  bool hourglassEnabled() const { return alpha_ != 0.0; }
  double hourglassCoefficient() const { return alpha_; }

  // Overwrites f with the internal plus hourglass force on every particle (ghosts included:
  // on a prescribed particle it is the reaction).
  void compute(const std::vector<Vec<D>>& u, std::vector<Vec<D>>& f) {
    for (std::size_t m = 0; m < materials_.size(); ++m)
      std::visit(
          [&](const auto& model) { deformationAndStress(model, particlesOfMaterial_[m], u); },
          materials_[m]);
    if (hourglassEnabled())
      accumulateForces<true>(u, f);
    else
      accumulateForces<false>(u, f);
  }

  const std::vector<Mat<D>>& deformationGradient() const { return F_; }
  // Hourglass part of the last computed force (empty when the term is off).
  const std::vector<Vec<D>>& hourglassForce() const { return hourglassForce_; }

  // First Piola-Kirchhoff stress of particle i at the last computed F.
  Mat<D> firstPiola(Index i) const { return P_[i]; }

  // E = sum_I V_I psi(F_I) at the last computed F: the discrete strain energy whose negative
  // gradient is the internal force.
  double strainEnergy() const {
    double total = 0.0;
    for (std::size_t m = 0; m < materials_.size(); ++m) {
      const auto& group = particlesOfMaterial_[m];
      total += std::visit(
          [&](const auto& model) {
            double sum = 0.0;
            const Index count = static_cast<Index>(group.size());
#pragma omp parallel for reduction(+ : sum) schedule(static)
            for (Index p = 0; p < count; ++p)
              sum += volume_[group[p]] * strainEnergyDensity<D>(model, F_[group[p]]);
            return sum;
          },
          materials_[m]);
    }
    return total;
  }

 private:
  template <class Model>
  void deformationAndStress(const Model& model, const std::vector<Index>& group,
                            const std::vector<Vec<D>>& u) {
    if (separateHourglassGradient_) {
      // The penalty's own (linear-corrected) deformation gradient.
      const auto& nb = ref_.neighbours;
      const Index count = static_cast<Index>(group.size());
#pragma omp parallel for schedule(static)
      for (Index p = 0; p < count; ++p) {
        const Index i = group[p];
        Mat<D> gradU = Mat<D>::Zero();
        for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k)
          gradU.noalias() += (u[nb.neighbour[k]] - u[i]) * ref_.linearGradient[k].transpose();
        hourglassF_[i] = Mat<D>::Identity() + gradU;
      }
    }
    const auto& nb = ref_.neighbours;
    const Index count = static_cast<Index>(group.size());
#pragma omp parallel for schedule(static)
    for (Index p = 0; p < count; ++p) {
      const Index i = group[p];
      const Vec<D> ui = u[i];
      Mat<D> gradU = Mat<D>::Zero();
      for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k)
        gradU.noalias() += (u[nb.neighbour[k]] - ui) * ref_.correctedGradient[k].transpose();
      const Mat<D> F = Mat<D>::Identity() + gradU;  // (6.69)
      F_[i] = F;
      P_[i] = firstPiolaKirchhoff<D>(model, F);
    }
  }

  template <bool Hourglass>
  void accumulateForces(const std::vector<Vec<D>>& u, std::vector<Vec<D>>& f) {
    const auto& nb = ref_.neighbours;
    const Index n = ref_.particleCount();
#pragma omp parallel for schedule(static)
    for (Index i = 0; i < n; ++i) {
      // (6.70) as a force: f_I = V_I (P_I G_I - sum_J P_J t_IJ)
      Vec<D> internal = P_[i] * ref_.correctedGradientSum[i];
      Vec<D> hourglass = Vec<D>::Zero();
      const Vec<D> ui = u[i];
      const std::vector<Mat<D>>& Fh = separateHourglassGradient_ ? hourglassF_ : F_;
      const Mat<D> Fi = Fh[i];
      for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k) {
        const Index j = nb.neighbour[k];
        internal.noalias() -= P_[j] * ref_.reverseGradient[k];
        if constexpr (Hourglass) {
          const Vec<D>& Xij = ref_.separation[k];
          const Vec<D> xij = Xij + (ui - u[j]);
          const Vec<D> error = xij - 0.5 * ((Fi + Fh[j]) * Xij);  // (6.81) before projection
          // (6.80): -c_IJ eps_IJ x_IJ/|x_IJ| with eps_IJ = error . x_IJ/|x_IJ|
          hourglass -= (hourglassStiffness_[k] * error.dot(xij) / xij.squaredNorm()) * xij;
        }
      }
      if constexpr (Hourglass) {
        hourglassForce_[i] = volume_[i] * hourglass;
        f[i] = volume_[i] * (internal + hourglass);
      } else {
        f[i] = volume_[i] * internal;
      }
    }
  }

  const ReferenceConfiguration<D>& ref_;
  const std::vector<Material>& materials_;
  const std::vector<std::uint16_t>& materialOfParticle_;
  const std::vector<double>& volume_;
  double alpha_;
  std::vector<std::vector<Index>> particlesOfMaterial_;
  std::vector<Mat<D>> F_;
  std::vector<Mat<D>> P_;
  bool separateHourglassGradient_ = false;
  std::vector<Mat<D>> hourglassF_;
  std::vector<double> hourglassStiffness_;
  std::vector<Vec<D>> hourglassForce_;
};

}  // namespace tlsph
