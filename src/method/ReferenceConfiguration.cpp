#include "method/ReferenceConfiguration.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "model/Errors.hpp"

namespace tlsph {

const char* gradientCorrectionName(GradientCorrection c) {
  return c == GradientCorrection::Linear ? "linear" : "quadratic";
}

GradientCorrection parseGradientCorrection(const std::string& name) {
  if (name == "linear") return GradientCorrection::Linear;
  if (name == "quadratic") return GradientCorrection::Quadratic;
  throw std::invalid_argument("unknown gradient correction '" + name +
                              "'; expected linear or quadratic");
}

const char* quadratureName(Quadrature q) {
  return q == Quadrature::Nodal ? "nodal" : "taylor";
}

Quadrature parseQuadrature(const std::string& name) {
  if (name == "nodal") return Quadrature::Nodal;
  if (name == "taylor") return Quadrature::Taylor;
  throw std::invalid_argument("unknown quadrature '" + name + "'; expected nodal or taylor");
}

namespace {

std::string conditionMessage(Index i, const std::string& position, Index neighbours,
                             const char* what, double condition, double needed, int D) {
  std::ostringstream msg;
  msg << "particle " << i << " at (" << position << ") has " << neighbours << " neighbours and its "
      << what << " is " << (condition == 0.0 ? "singular" : "badly conditioned")
      << " (reciprocal condition number " << condition << ", need at least " << needed
      << "); its neighbours must span all " << D
      << " directions: increase the kernel support H/dx or check the geometry";
  return msg.str();
}

}  // namespace

template <int D>
ReferenceConfiguration<D> buildReferenceConfiguration(
    const std::vector<Vec<D>>& X, const std::vector<double>& volume, const Kernel<D>& kernel,
    const PeriodicBox<D>& box, GradientCorrection correction, double minCorrectionCondition,
    const std::vector<Index>* rows) {
  ReferenceConfiguration<D> ref;
  ref.correction = correction;
  ref.neighbours = rows ? buildNeighbourRows<D>(X, *rows, kernel.supportRadius(), box)
                        : buildNeighbourList<D>(X, kernel.supportRadius(), box);
  const auto& nb = ref.neighbours;
  const Index n = ref.particleCount();
  const Index pairs = nb.pairCount();
  ref.separation.resize(pairs);
  ref.weightedGradient.resize(pairs);
  ref.kernelValue.resize(pairs);
  ref.correctedGradient.resize(pairs);
  ref.reverseGradient.resize(pairs);
  if (correction == GradientCorrection::Quadratic) ref.linearGradient.resize(pairs);
  ref.correctionInverse.assign(n, Mat<D>::Zero());
  ref.gradientSum.assign(n, Vec<D>::Zero());
  ref.correctedGradientSum.assign(n, Vec<D>::Zero());
  const double H = kernel.supportRadius();

  // The particles built: all, or the rows asked for.
  const Index built = rows ? static_cast<Index>(rows->size()) : n;
  auto particle = [&](Index q) { return rows ? (*rows)[q] : q; };
  std::vector<double> condition(n), fitCondition(n, 1.0);
#pragma omp parallel for schedule(static)
  for (Index q = 0; q < built; ++q) {
    const Index i = particle(q);
    Mat<D> L = Mat<D>::Zero();
    Vec<D> s = Vec<D>::Zero();
    for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k) {
      const Index j = nb.neighbour[k];
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

    Vec<D> G = Vec<D>::Zero();
    if (correction == GradientCorrection::Linear) {
      const Mat<D> LinvT = ref.correctionInverse[i].transpose();
      for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k) {
        ref.correctedGradient[k] = LinvT * ref.weightedGradient[k];  // (6.69)
        G += ref.correctedGradient[k];
      }
    } else {
      // Weighted least squares: f_J - f_I ~ c . p(Delta_J / H), weights V_J W_IJ; the
      // gradient is c_1..c_D / H, linear in the f_J: g_IJ = V_J W_IJ [M^{-1} p_J]_{1..D} / H.
      constexpr int T = kQuadraticTerms<D>;
      using Moment = Eigen::Matrix<double, T, T>;
      Moment M = Moment::Zero();
      for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k) {
        const auto p = quadraticBasis<D>(-ref.separation[k] / H);
        M.noalias() += (volume[nb.neighbour[k]] * ref.kernelValue[k]) * p * p.transpose();
      }
      // Dynamic size: set-up cost only.
      const Mat<D> LinvT = ref.correctionInverse[i].transpose();
      for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k)
        ref.linearGradient[k] = LinvT * ref.weightedGradient[k];
      const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen{Eigen::MatrixXd(M)};
      const double largest = eigen.eigenvalues().maxCoeff();
      fitCondition[i] =
          largest > 0.0 ? std::max(0.0, eigen.eigenvalues().minCoeff()) / largest : 0.0;
      // Too few neighbours on two levels for the fit (an acute corner, a strip two particles
      // thick): this particle keeps the linear correction (listed in linearFallback).
      if (fitCondition[i] < minCorrectionCondition * minCorrectionCondition) {
        for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k) {
          ref.correctedGradient[k] = ref.linearGradient[k];
          G += ref.correctedGradient[k];
        }
      } else {
        const Moment Minv =
            Moment(eigen.eigenvectors() * eigen.eigenvalues().cwiseInverse().asDiagonal() *
                   eigen.eigenvectors().transpose());
        for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k) {
          const auto p = quadraticBasis<D>(-ref.separation[k] / H);
          const Eigen::Matrix<double, T, 1> c = Minv * p;
          ref.correctedGradient[k] =
              (volume[nb.neighbour[k]] * ref.kernelValue[k] / H) * c.template head<D>();
          G += ref.correctedGradient[k];
        }
      }
    }
    ref.correctedGradientSum[i] = G;
  }

  for (Index q = 0; q < built; ++q) {
    const Index i = particle(q);
    std::ostringstream position;
    if (condition[i] < minCorrectionCondition) {
      position << X[i].transpose();
      throw SetupError(conditionMessage(i, position.str(), nb.count(i), "correction tensor L",
                                        condition[i], minCorrectionCondition, D));
    }
    // The fit's moment matrix is a Gram matrix of monomials: its eigenvalue ratio is the
    // square of a condition number, so the bar is squared too.
    if (fitCondition[i] < minCorrectionCondition * minCorrectionCondition)
      ref.linearFallback.push_back(i);
  }

  if (rows) {
    ref.rowMask.assign(n, 0);
    for (Index i : *rows)
      ref.rowMask[i] = 1;
  }
  ref.reverseGradient = reverseVectors<D>(nb, ref.correctedGradient, volume, ref.rows());
  return ref;
}

void throwAsymmetricNeighbourLists() {
  throw SetupError("internal: neighbour lists are not symmetric");
}

template ReferenceConfiguration<2> buildReferenceConfiguration<2>(
    const std::vector<Vec<2>>&, const std::vector<double>&, const Kernel<2>&, const PeriodicBox<2>&,
    GradientCorrection, double, const std::vector<Index>*);
template ReferenceConfiguration<3> buildReferenceConfiguration<3>(
    const std::vector<Vec<3>>&, const std::vector<double>&, const Kernel<3>&, const PeriodicBox<3>&,
    GradientCorrection, double, const std::vector<Index>*);

}  // namespace tlsph
