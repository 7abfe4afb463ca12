// Everything a total-Lagrangian step needs from the reference configuration, computed once:
// neighbour lists, per-pair kernel data and the inverse correction tensors L_I^{-1}.
#pragma once

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "method/Kernel.hpp"
#include "method/NeighbourList.hpp"
#include "model/PeriodicBox.hpp"
#include "model/Types.hpp"

namespace tlsph {

[[noreturn]] void throwAsymmetricNeighbourLists();

// How the gradient of a particle field is corrected (docs/method.md section 2, and README):
//   Linear: (6.69), gradW times L_I^{-1}; exact for linear fields.
//   Quadratic: the gradient of a kernel-weighted least-squares quadratic fit through the
//   particle's value; exact for quadratic fields, so also on free surfaces in bending, where
//   the linear correction reads the strain at the neighbourhood's centroid, inside the body.
enum class GradientCorrection { Linear, Quadratic };

// Monomials of the quadratic correction's fit through the particle's own value, in a scaled
// offset d: d_1..d_D, then d_a d_b for a <= b (also TaylorQuadrature's second derivatives).
template <int D>
constexpr int kQuadraticTerms = D + D*(D + 1) / 2;

template <int D>
Eigen::Matrix<double, kQuadraticTerms<D>, 1> quadraticBasis(const Vec<D>& d) {
  Eigen::Matrix<double, kQuadraticTerms<D>, 1> p;
  int t = 0;
  for (int a = 0; a < D; ++a)
    p[t++] = d[a];
  for (int a = 0; a < D; ++a)
    for (int b = a; b < D; ++b)
      p[t++] = d[a] * d[b];
  return p;
}
// How the strain energy is integrated over the particles ([kernel] quadrature): the one-point
// nodal sum, or that sum with its second-order Taylor term (TaylorQuadrature.hpp; needs the
// quadratic correction's fit).
enum class Quadrature { Nodal, Taylor };

const char* gradientCorrectionName(GradientCorrection c);
GradientCorrection parseGradientCorrection(const std::string& name);  // invalid_argument
const char* quadratureName(Quadrature q);
Quadrature parseQuadrature(const std::string& name);  // invalid_argument

// What the integration constraint (IntegrationConstraint.hpp) did to the gradient vectors.
struct IntegrationConstraintSummary {
  bool applied = false;
  double defectBefore = 0.0;  // max_I |a_I - d_I| / max_I |a_I|
  double defectAfter = 0.0;
  int iterations = 0;       // conjugate-gradient iterations
  bool factorised = false;  // preconditioned by a Cholesky factor (else by the diagonal)
  double seconds = 0.0;     // wall time of the whole correction
  // The linear-stress constraint: its first moments' defect max_I |b_I - V_I 1 - m_I| / V_I
  // before and after, the filter, and the correction's size |delta| / |g| over all pairs.
  bool linear = false;
  double momentDefectBefore = 0.0;
  double momentDefectAfter = 0.0;
  double filter = 0.0;
  double correction = 0.0;
};

template <int D>
struct ReferenceConfiguration {
  NeighbourList neighbours;
  // Per pair (I, J), in CSR order:
  PairArray<Vec<D>> separation;        // X_IJ = X_I - X_J (minimum image)
  PairArray<Vec<D>> weightedGradient;  // w_IJ = V_J gradW_IJ
  PairArray<double> kernelValue;       // W(X_IJ)
  // g_IJ: grad f_I = sum_J (f_J - f_I) g_IJ, so F_I = 1 + sum_J (u_J - u_I) (x) g_IJ.
  // Linear correction: g_IJ = L_I^{-T} w_IJ.
  PairArray<Vec<D>> correctedGradient;
  // Quadratic correction only: the linear g_IJ = L_I^{-T} w_IJ as well, for the hourglass
  // penalty's smooth field F_I X_IJ (with the quadratic F the penalty turns unstable).
  PairArray<Vec<D>> linearGradient;
  // t_IJ = (V_J / V_I) g_JI, the reverse pair's vector, so the force -dE/du_I is
  // V_I (P_I G_I - sum_J P_J t_IJ) with one pass over I's own list.
  PairArray<Vec<D>> reverseGradient;
  // Per particle:
  std::vector<Mat<D>> correctionInverse;     // L_I^{-1}, (6.44)
  std::vector<Vec<D>> gradientSum;           // s_I = sum_J w_IJ
  std::vector<Vec<D>> correctedGradientSum;  // G_I = sum_J g_IJ
  GradientCorrection correction = GradientCorrection::Linear;
  // Quadratic correction only: particles whose neighbourhood cannot carry the quadratic fit
  // (an acute corner, a strip two particles thick) and use the linear g_IJ instead.
  std::vector<Index> linearFallback;
  // Built for some particles only (buildReferenceConfiguration's rows): 1 for those; empty
  // when built for all.
  std::vector<std::uint8_t> rowMask;
  // The gradient vectors' correction for the integration constraint (mesh bodies).
  IntegrationConstraintSummary integrationConstraint;

  Index particleCount() const { return neighbours.particleCount(); }
  // For reversePairValues: null when every particle has its list.
  const std::vector<std::uint8_t>* rows() const { return rowMask.empty() ? nullptr : &rowMask; }
};

// t_IJ = (V_J / V_I) a_JI for every pair (I, J) of the (symmetric, sorted) full lists: the
// reverse pair's value, so a force -dE/du_I is gathered from I's own list. (J, I) is found by
// binary search in J's sorted list. Throws SetupError if a list is not symmetric.
// hasRow (lists built for some particles only, buildNeighbourRows): a pair whose neighbour has
// no list of its own gets zero.
// valueOf(k): a_k for pair k (reversePairValuesOf, for values stored inside larger records).
template <class Value, class ValueOf>
PairArray<Value> reversePairValuesOf(const NeighbourList& nb, ValueOf&& valueOf,
                                     const std::vector<double>& volume,
                                     const std::vector<std::uint8_t>* hasRow = nullptr) {
  PairArray<Value> t(nb.pairCount());
  const Index n = nb.particleCount();
  bool symmetric = true;
#pragma omp parallel for reduction(&& : symmetric) schedule(static)
  for (Index i = 0; i < n; ++i)
    for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k) {
      const Index j = nb.neighbour[k];
      if (hasRow && !(*hasRow)[j]) {
        t[k] = Value::Zero();
        continue;
      }
      const auto first = nb.neighbour.begin() + nb.offset[j];
      const auto last = nb.neighbour.begin() + nb.offset[j + 1];
      const auto at = std::lower_bound(first, last, i);
      if (at == last || *at != i) {
        symmetric = false;
        continue;
      }
      t[k] = (volume[j] / volume[i]) * valueOf(Index(at - nb.neighbour.begin()));
    }
  if (!symmetric) throwAsymmetricNeighbourLists();
  return t;
}

template <class Value>
PairArray<Value> reversePairValues(const NeighbourList& nb, const PairArray<Value>& a,
                                   const std::vector<double>& volume,
                                   const std::vector<std::uint8_t>* hasRow = nullptr) {
  return reversePairValuesOf<Value>(
      nb, [&](Index k) -> const Value& { return a[k]; }, volume, hasRow);
}

template <int D>
PairArray<Vec<D>> reverseVectors(const NeighbourList& nb, const PairArray<Vec<D>>& g,
                                 const std::vector<double>& volume,
                                 const std::vector<std::uint8_t>* hasRow = nullptr) {
  return reversePairValues(nb, g, volume, hasRow);
}

// Smallest accepted reciprocal condition number of L_I (sigma_min / sigma_max).
inline constexpr double kDefaultMinCorrectionCondition = 1e-6;

// Throws SetupError naming the particle whose L_I is singular or badly conditioned.
// rows: build the lists and pair data of these particles only (ascending; the others' lists
// are empty), each row exactly as the whole build gives it, its reverse vectors wherever the
// neighbour is a row too: a distributed run's own particles and halo.
template <int D>
ReferenceConfiguration<D> buildReferenceConfiguration(
    const std::vector<Vec<D>>& X, const std::vector<double>& volume, const Kernel<D>& kernel,
    const PeriodicBox<D>& box = {}, GradientCorrection correction = GradientCorrection::Linear,
    double minCorrectionCondition = kDefaultMinCorrectionCondition,
    const std::vector<Index>* rows = nullptr);

}  // namespace tlsph
