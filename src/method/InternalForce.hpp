// The internal force (6.70) as the exact negative gradient of the discrete strain energy
//   E = sum_I V_I psi(F_I),   F_I = 1 + sum_J (u_J - u_I) (x) g_IJ   (6.69),
// written as the pair sum: F_I depends on u_J through g_IJ and on u_I through -sum_J g_IJ, so
// each pair (I, J) of I's list sends V_I P_I g_IJ to J and takes it from I:
//   f = -dE/du:   f_J -= V_I P_I g_IJ,   f_I += V_I P_I g_IJ,   P_I = dpsi/dF (F_I).
// With the linear correction, g_IJ = L_I^{-T} V_J gradW_IJ, gathering both directions of every
// pair gives the chapter's form f_I = V_I sum_J V_J (P_I L_I^{-T} + P_J L_J^{-T}) gradW_IJ.
// Every pair adds and takes the same vector, so the total force is zero (linear momentum); E
// is invariant under rigid rotations of an F exact for them, so the torque is zero too.
// The same sum sends any stress through any gradient vectors: the hourglass stress through
// the penalty's F (HourglassEnergy.hpp), P + P^q through the quadratic fit (TaylorCorrection).
#pragma once

#include <cstdint>
#include <vector>

#include "materials/Material.hpp"
#include "method/ReferenceConfiguration.hpp"
#include "model/Types.hpp"

namespace tlsph {

// f -= sum_I V_I S_I : dF_I/du, F_I through the gradient vectors g: the pair sum. With S = P
// that is -dE/du; with another stress, the part of a force that goes through F.
template <int D>
void addStressDivergence(const NeighbourList& nb, const PairArray<Vec<D>>& g,
                         const std::vector<double>& volume, const std::vector<Mat<D>>& S,
                         std::vector<Vec<D>>& f) {
  for (Index i = 0; i < nb.particleCount(); ++i)
    for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k) {
      const Index j = nb.neighbour[k];
      const Vec<D> sent = volume[i] * (S[i] * g[k]);  // (6.70), one pair's share
      f[j] -= sent;
      f[i] += sent;
    }
}

// P_I = dpsi/dF of each particle's material; zero for passive particles (mirrored ghosts,
// which carry no energy of their own).
template <int D>
std::vector<Mat<D>> firstPiolaKirchhoffStresses(const std::vector<Material>& materials,
                                                const std::vector<std::uint16_t>& materialOf,
                                                const std::vector<Mat<D>>& F,
                                                const std::vector<std::uint8_t>& passive = {}) {
  const Index n = static_cast<Index>(F.size());
  std::vector<Mat<D>> P(n, Mat<D>::Zero());
#pragma omp parallel for schedule(static)
  for (Index i = 0; i < n; ++i)
    if (passive.empty() || !passive[i])
      P[i] = firstPiolaKirchhoff<D>(materials[materialOf[i]], F[i]);
  return P;
}

// E = sum_I V_I psi(F_I) over the particles that are not passive.
template <int D>
double strainEnergy(const std::vector<Material>& materials,
                    const std::vector<std::uint16_t>& materialOf, const std::vector<double>& volume,
                    const std::vector<Mat<D>>& F, const std::vector<std::uint8_t>& passive = {}) {
  double E = 0.0;
  for (std::size_t i = 0; i < F.size(); ++i)
    if (passive.empty() || !passive[i])
      E += volume[i] * strainEnergyDensity<D>(materials[materialOf[i]], F[i]);
  return E;
}

// The internal force (6.70) for the stresses P of the scene's F: zeroes f first.
template <int D>
std::vector<Vec<D>> internalForce(const ReferenceConfiguration<D>& ref,
                                  const std::vector<double>& volume, const std::vector<Mat<D>>& P) {
  std::vector<Vec<D>> f(ref.particleCount(), Vec<D>::Zero());
  addStressDivergence<D>(ref.neighbours, ref.correctedGradient, volume, P, f);
  return f;
}

}  // namespace tlsph
