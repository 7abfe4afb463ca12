#include "tlsph/ReferenceConfiguration.hpp"

#include <Eigen/LU>
#include <cmath>
#include <sstream>

#include "tlsph/Errors.hpp"

namespace tlsph {

template <int D>
ReferenceConfiguration<D> buildReferenceConfiguration(const std::vector<Vec<D>>& X,
                                                      const std::vector<double>& volume,
                                                      const Kernel<D>& kernel,
                                                      const PeriodicBox<D>& box,
                                                      double minCorrectionCondition) {
  ReferenceConfiguration<D> ref;
  ref.neighbours = buildNeighbourList<D>(X, kernel.supportRadius(), box);
  const Index n = ref.particleCount();
  const Index pairs = ref.neighbours.pairCount();
  ref.separation.resize(pairs);
  ref.weightedGradient.resize(pairs);
  ref.kernelValue.resize(pairs);
  ref.correctionInverse.resize(n);
  ref.gradientSum.resize(n);

  std::vector<double> condition(n);
#pragma omp parallel for schedule(static)
  for (Index i = 0; i < n; ++i) {
    Mat<D> L = Mat<D>::Zero();
    Vec<D> s = Vec<D>::Zero();
    for (Index k = ref.neighbours.offset[i]; k < ref.neighbours.offset[i + 1]; ++k) {
      const Index j = ref.neighbours.neighbour[k];
      const Vec<D> Xij = box.separation(X[i], X[j]);
      const Vec<D> w = volume[j] * kernel.gradient(Xij);
      ref.separation[k] = Xij;
      ref.weightedGradient[k] = w;
      ref.kernelValue[k] = kernel.value(Xij.norm());
      L -= Xij * w.transpose();  // (6.44): L_I = sum_J V_J (X_J - X_I) (x) gradW_IJ
      s += w;
    }
    // Reciprocal Frobenius condition number 1 / (|L| |L^{-1}|): within a factor D of the
    // 2-norm one, and 0 when L is singular.
    const double det = L.determinant();
    ref.correctionInverse[i] = det != 0.0 ? Mat<D>(L.inverse()) : Mat<D>::Zero();
    const double product = L.norm() * ref.correctionInverse[i].norm();
    condition[i] = det != 0.0 && std::isfinite(product) ? 1.0 / product : 0.0;
    ref.gradientSum[i] = s;
  }

  for (Index i = 0; i < n; ++i) {
    if (condition[i] >= minCorrectionCondition) continue;
    std::ostringstream msg;
    msg << "particle " << i << " at (" << X[i].transpose() << ") has " << ref.neighbours.count(i)
        << " neighbours and its correction tensor L is "
        << (condition[i] == 0.0 ? "singular" : "badly conditioned")
        << " (reciprocal condition number " << condition[i] << ", need at least "
        << minCorrectionCondition << "); its neighbours must span all " << D
        << " directions: increase the kernel support H/dx or check the geometry";
    throw SetupError(msg.str());
  }
  return ref;
}

template ReferenceConfiguration<2> buildReferenceConfiguration<2>(const std::vector<Vec<2>>&,
                                                                  const std::vector<double>&,
                                                                  const Kernel<2>&,
                                                                  const PeriodicBox<2>&, double);
template ReferenceConfiguration<3> buildReferenceConfiguration<3>(const std::vector<Vec<3>>&,
                                                                  const std::vector<double>&,
                                                                  const Kernel<3>&,
                                                                  const PeriodicBox<3>&, double);

}  // namespace tlsph
