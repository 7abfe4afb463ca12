// What a body read from a file must satisfy before its pair data is built, and what its
// particles' arrangement says about the kernel support the quadratic fit needs.
//
// Volume density: where particles tile the body, the kernel-weighted sum of their volumes,
//   rho_I = sum_J V_J W(|X_J - X_I|)   (J = I included),
// is the kernel's integral over the body near X_I: about 1 inside, 0.88 half a spacing inside
// a flat face (2D, support 2.1), less at an edge or a corner. Where two volumes or two clouds
// overlap the volumes count twice and rho_I is about 2, whatever the particles' arrangement. So
// rho_I above kOverlapDensity names an overlap. Measured largest rho_I at support 2.1:
// lattice 1.03, jitter 5 % / 20 % of dx 1.07 / 1.24, gmsh nodes with their hats' volumes 1.17-1.27;
// a doubled cloud 2.01.
//
// Lattice: the fit's second layer of neighbours across a flat face is one particle at 2 dx,
// weighted W(2 / 2.1) ~ 1e-5 of the first layer's at the default support 2.1. On a lattice it
// is exact and the fit is the one-sided difference; off it, the first layer's scatter carries
// more weight than that particle and the face's gradient vectors grow as 1 / scatter (the
// operator's highest frequency rises, the explicit step falls 10-25x at 5 % of dx). Measured
// (tlsph_bench, quadratic fit, Taylor term): jitter 1e-4 dx leaves the spectral cap above the
// rule, 1e-3 dx halves it. A set within kLatticeTolerance of a lattice is one.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "method/Kernel.hpp"
#include "method/NeighbourList.hpp"
#include "model/Types.hpp"

namespace tlsph {

inline constexpr double kOverlapDensity = 1.5;
// Two particles closer than this fraction of the smaller one's spacing V^(1/d) are one particle
// to the kernel and make the fit singular. Measured nearest pairs: lattice 1, jitter 5 % / 20 %
// of dx 0.90 / 0.61, gmsh nodes (the bracket, the Lame ring and cylinder, the plate with a
// hole) 0.76-0.82.
inline constexpr double kCloseRatio = 0.25;
inline constexpr double kLatticeTolerance = 1e-4;  // of the spacing
// The support off the lattice: the fit's second layer (9 particles across a face at 2.5 dx,
// 1 at 2.1) then carries the curvature, and the cap leaves the rule's step (up to 20 % of dx).
inline constexpr double kOffLatticeSupportRatio = 2.5;

struct DensityPeak {
  Index particle = -1;   // the largest rho_I
  double density = 0.0;  // its value
  Index closest = -1;    // its nearest other particle
  double distance = 0.0;
};

// rho_I of every particle; nb: the lists within the kernel's support.
template <int D>
std::vector<double> volumeDensity(const std::vector<Vec<D>>& X, const std::vector<double>& V,
                                  const Kernel<D>& kernel, const NeighbourList& nb) {
  std::vector<double> rho(X.size());
  for (Index i = 0; i < nb.particleCount(); ++i) {
    double sum = V[i] * kernel.value(0.0);
    for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k)
      sum += V[nb.neighbour[k]] * kernel.value((X[nb.neighbour[k]] - X[i]).norm());
    rho[i] = sum;
  }
  return rho;
}

// The two particles closest for their size: the least |X_J - X_I| / min(h_I, h_J), h = V^(1/d).
struct ClosestPair {
  Index first = -1, second = -1;
  double ratio = std::numeric_limits<double>::infinity();
};

// (Among the pairs of nb.)
template <int D>
ClosestPair closestPair(const std::vector<Vec<D>>& X, const std::vector<double>& V,
                        const NeighbourList& nb) {
  ClosestPair best;
  for (Index i = 0; i < nb.particleCount(); ++i)
    for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k) {
      const Index j = nb.neighbour[k];
      const double h = std::pow(std::min(V[i], V[j]), 1.0 / D);
      const double ratio = (X[j] - X[i]).norm() / h;
      if (j > i && ratio < best.ratio) best = {i, j, ratio};
    }
  return best;
}

// The particle with the largest rho_I and its nearest neighbour (for the message).
template <int D>
DensityPeak densityPeak(const std::vector<Vec<D>>& X, const std::vector<double>& V,
                        const Kernel<D>& kernel, const NeighbourList& nb) {
  DensityPeak peak;
  if (X.empty()) return peak;
  const std::vector<double> rho = volumeDensity<D>(X, V, kernel, nb);
  const auto top = std::max_element(rho.begin(), rho.end());
  peak.particle = static_cast<Index>(top - rho.begin());
  peak.density = *top;
  peak.distance = std::numeric_limits<double>::infinity();
  for (Index j = 0; j < static_cast<Index>(X.size()); ++j) {
    const double r = (X[j] - X[peak.particle]).norm();
    if (j != peak.particle && r < peak.distance) {
      peak.distance = r;
      peak.closest = j;
    }
  }
  return peak;
}

// Whether the particles are the cell centres of one lattice: equal volumes V = h^d, and every
// offset from the first particle a whole number of h along each axis, to kLatticeTolerance h.
template <int D>
bool onCellCentredLattice(const std::vector<Vec<D>>& X, const std::vector<double>& V) {
  if (X.empty()) return true;
  const double h = std::pow(V[0], 1.0 / D);
  if (!(h > 0.0)) return false;
  for (std::size_t i = 0; i < X.size(); ++i) {
    if (std::abs(V[i] - V[0]) > 1e-9 * V[0]) return false;
    for (int a = 0; a < D; ++a) {
      const double n = (X[i][a] - X[0][a]) / h;
      if (std::abs(n - std::round(n)) > kLatticeTolerance) return false;
    }
  }
  return true;
}

}  // namespace tlsph
