// The integration constraint's correction of the gradient vectors (IntegrationConstraint.hpp),
// compiled once for 2D and 3D: a set-up cost, one preconditioned conjugate-gradient solve per body.
#include "method/IntegrationConstraint.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <chrono>
#include <cmath>

#include "implicit/SparseCholesky.hpp"
#include "method/TaylorCorrection.hpp"
#include "model/Errors.hpp"

namespace tlsph {

template <int D>
std::vector<Vec<D>> quadratureDefect(const NeighbourList& nb, const PairArray<Vec<D>>& v,
                                     const std::vector<double>& volume) {
  std::vector<Vec<D>> d(nb.particleCount(), Vec<D>::Zero());
  for (Index i = 0; i < nb.particleCount(); ++i)
    for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k) {
      const Vec<D> sent = volume[i] * v[k];
      d[nb.neighbour[k]] += sent;
      d[i] -= sent;
    }
  return d;
}

template <int D>
PairArray<Vec<D>> taylorPairVectors(const ReferenceConfiguration<D>& ref,
                                    const std::vector<double>& volume,
                                    const QuadratureMoments<D>& moments) {
  const auto& nb = ref.neighbours;
  PairArray<Vec<D>> h(nb.pairCount(), Vec<D>::Zero());
  if (moments.lattice() || ref.correction != GradientCorrection::Quadratic) return h;
  std::vector<std::uint8_t> fallback(ref.particleCount(), 0);
  for (Index i : ref.linearFallback)
    fallback[i] = 1;
#pragma omp parallel for schedule(static)
  for (Index i = 0; i < ref.particleCount(); ++i) {
    if (fallback[i] || nb.count(i) == 0 || moments.offset[i].isZero()) continue;
    const std::vector<Mat<D>> S = fitSecondDerivatives<D>(ref, volume, i);
    for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k)
      h[k] = S[k - nb.offset[i]] * moments.offset[i];
  }
  return h;
}

namespace {

// The solve's budget: the defect's 2-norm falls below this fraction of its start, or the
// iterations run out (the best iterate is kept).
constexpr double kIntegrationTolerance = 1e-6;
constexpr int kIntegrationIterations = 3000;
// The preconditioner's shift, relative to the diagonal: it must keep the factorisation of the
// semi-definite matrix (null space: the polynomial lambda) safe from rounding.
constexpr double kIntegrationShift = 1e-9;

// Per particle K: the W-orthogonal projector onto the pair values that the fit's monomials
// annihilate, Pi_K y = W y - W P^T M^{-1} P W y, kept as the scaled monomials of each pair and
// M^{-1} (the quadratic monomials' rows and columns zero where only the linear ones count).
template <int D>
struct Projectors {
  static constexpr int T = kQuadraticTerms<D>;
  using Basis = Eigen::Matrix<double, T, 1>;
  using Moment = Eigen::Matrix<double, T, T>;
  PairArray<Basis> basis;
  PairArray<double> weight;
  std::vector<Moment> inverse;

  Projectors(const ReferenceConfiguration<D>& ref, const std::vector<double>& volume) {
    const auto& nb = ref.neighbours;
    const Index n = ref.particleCount();
    basis.resize(nb.pairCount());
    weight.resize(nb.pairCount());
    inverse.assign(n, Moment::Zero());
    std::vector<std::uint8_t> linearOnly(n, ref.correction != GradientCorrection::Quadratic);
    for (Index i : ref.linearFallback)
      linearOnly[i] = 1;
#pragma omp parallel for schedule(static)
    for (Index i = 0; i < n; ++i) {
      double l = 0.0;  // scale of the offsets, for conditioning only
      for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k)
        l = std::max(l, ref.separation[k].norm());
      if (l == 0.0) continue;
      const int terms = linearOnly[i] ? D : T;
      Moment M = Moment::Zero();
      for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k) {
        basis[k] = quadraticBasis<D>(-ref.separation[k] / l);
        if (terms < T) basis[k].template tail<T - D>().setZero();
        weight[k] = volume[nb.neighbour[k]];
        M.noalias() += weight[k] * basis[k] * basis[k].transpose();
      }
      const Eigen::SelfAdjointEigenSolver<Moment> eigen(M);
      // A pseudo-inverse: directions the neighbourhood cannot resolve are not constrained.
      const auto values = eigen.eigenvalues();
      const double floor = 1e-12 * std::max(values.maxCoeff(), 0.0);
      Basis inv = Basis::Zero();
      for (int t = 0; t < T; ++t)
        if (values[t] > floor) inv[t] = 1.0 / values[t];
      inverse[i] = eigen.eigenvectors() * inv.asDiagonal() * eigen.eigenvectors().transpose();
    }
  }

  // z_K = Pi_K y_K for every particle K (pair values with D components each).
  void apply(const NeighbourList& nb, const PairArray<Vec<D>>& y, PairArray<Vec<D>>& z) const {
#pragma omp parallel for schedule(static)
    for (Index i = 0; i < nb.particleCount(); ++i) {
      Eigen::Matrix<double, T, D> t = Eigen::Matrix<double, T, D>::Zero();  // P W y
      for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k)
        t.noalias() += (weight[k] * basis[k]) * y[k].transpose();
      const Eigen::Matrix<double, T, D> s = inverse[i] * t;
      for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k)
        z[k] = weight[k] * (y[k] - s.transpose() * basis[k]);
    }
  }
};

// For every pair k = (I, J): the index of (J, I) in J's list.
PairArray<Index> reversePairIndex(const NeighbourList& nb) {
  PairArray<Index> rev(nb.pairCount(), -1);
#pragma omp parallel for schedule(static)
  for (Index i = 0; i < nb.particleCount(); ++i)
    for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k) {
      const Index j = nb.neighbour[k];
      const auto first = nb.neighbour.begin() + nb.offset[j];
      const auto last = nb.neighbour.begin() + nb.offset[j + 1];
      const auto at = std::lower_bound(first, last, i);
      if (at != last && *at == i) rev[k] = Index(at - nb.neighbour.begin());
    }
  for (Index r : rev)
    if (r < 0) throwAsymmetricNeighbourLists();
  return rev;
}

// The matrix of A Pi A^T for one component (it is the same for every component), its lower
// triangle. Particle K's block couples K with its neighbours: the pair values y_KJ =
// V_K (lambda_J - lambda_K) are V_K C (lambda_J..., lambda_K) with C = [I | -1], so the block is
// V_K^2 C^T Pi_K C: Pi_K(J, J') between neighbours, minus its row sums s_J between a neighbour
// and K, and sum_J s_J on K's diagonal.
template <int D>
SparseCholesky::Matrix constraintMatrix(const NeighbourList& nb, const Projectors<D>& projector,
                                        const std::vector<double>& volume) {
  using Basis = typename Projectors<D>::Basis;
  const Index n = nb.particleCount();
  // Column j's rows (>= j): every particle sharing a block with j, i.e. in the list of j or of
  // one of j's neighbours (the lists are symmetric).
  std::vector<int> start(n + 1, 0);
  std::vector<std::vector<int>> rows(n);
#pragma omp parallel
  {
    std::vector<std::uint8_t> seen(n, 0);
#pragma omp for schedule(dynamic, 64)
    for (Index j = 0; j < n; ++j) {
      auto& r = rows[j];
      auto add = [&](Index i) {
        if (i >= j && !seen[i]) {
          seen[i] = 1;
          r.push_back(i);
        }
      };
      auto block = [&](Index K) {
        add(K);
        for (Index k = nb.offset[K]; k < nb.offset[K + 1]; ++k)
          add(nb.neighbour[k]);
      };
      block(j);
      for (Index k = nb.offset[j]; k < nb.offset[j + 1]; ++k)
        block(nb.neighbour[k]);
      for (Index i : r)
        seen[i] = 0;
      std::sort(r.begin(), r.end());
    }
  }
  for (Index j = 0; j < n; ++j)
    start[j + 1] = start[j] + int(rows[j].size());
  std::vector<int> inner(start[n]);
  for (Index j = 0; j < n; ++j) {
    std::copy(rows[j].begin(), rows[j].end(), inner.begin() + start[j]);
    std::vector<int>().swap(rows[j]);
  }
  std::vector<double> value(start[n], 0.0);
  auto entry = [&](Index a, Index b) -> double& {
    const Index col = std::min(a, b), row = std::max(a, b);
    const auto first = inner.begin() + start[col], last = inner.begin() + start[col + 1];
    return value[std::lower_bound(first, last, row) - inner.begin()];
  };

#pragma omp parallel
  {
    std::vector<Basis> q;
    std::vector<double> rowSum;
#pragma omp for schedule(dynamic, 16)
    for (Index K = 0; K < n; ++K) {
      const Index first = nb.offset[K], count = nb.count(K);
      if (count == 0) continue;
      const auto& Minv = projector.inverse[K];
      q.resize(count);
      rowSum.resize(count);
      Basis sigma = Basis::Zero();
      for (Index a = 0; a < count; ++a) {
        q[a] = Minv * projector.basis[first + a];
        sigma += projector.weight[first + a] * projector.basis[first + a];
      }
      const double scale = volume[K] * volume[K];
      double own = 0.0;
      for (Index a = 0; a < count; ++a) {
        const double wa = projector.weight[first + a];
        rowSum[a] = wa - wa * q[a].dot(sigma);
        own += rowSum[a];
        const Index J = nb.neighbour[first + a];
        for (Index b = 0; b <= a; ++b) {
          const Index L = nb.neighbour[first + b];
          double pi = -wa * projector.weight[first + b] * q[a].dot(projector.basis[first + b]);
          if (a == b) pi += wa;
          double& e = entry(J, L);
#pragma omp atomic
          e += scale * pi;
        }
        double& coupling = entry(J, K);
#pragma omp atomic
        coupling -= scale * rowSum[a];
      }
      double& diagonal = entry(K, K);
#pragma omp atomic
      diagonal += scale * own;
    }
  }
  return SparseCholesky::Matrix(Eigen::Map<const SparseCholesky::Matrix>(
      n, n, start[n], start.data(), inner.data(), value.data()));
}

// After the gradient vectors changed: their per-particle sums and the reverse vectors.
template <int D>
void refreshGradientSums(ReferenceConfiguration<D>& ref, const std::vector<double>& volume) {
  const auto& nb = ref.neighbours;
  for (Index i = 0; i < ref.particleCount(); ++i) {
    Vec<D> G = Vec<D>::Zero();
    for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k)
      G += ref.correctedGradient[k];
    ref.correctedGradientSum[i] = G;
  }
  ref.reverseGradient = reverseVectors<D>(nb, ref.correctedGradient, volume, ref.rows());
}

}  // namespace

template <int D>
void enforceIntegrationConstraint(ReferenceConfiguration<D>& ref, const std::vector<Vec<D>>& X,
                                  const std::vector<double>& volume,
                                  const std::vector<Vec<D>>& boundaryArea,
                                  const PairArray<Vec<D>>& extra) {
  const auto& nb = ref.neighbours;
  const Index n = ref.particleCount();
  if (static_cast<Index>(boundaryArea.size()) != n)
    throw SetupError("the boundary's area vectors are not one per particle");
  auto defect = [&]() {
    PairArray<Vec<D>> v = ref.correctedGradient;
    if (!extra.empty())
      for (Index k = 0; k < nb.pairCount(); ++k)
        v[k] += extra[k];
    const std::vector<Vec<D>> d = quadratureDefect<D>(nb, v, volume);
    std::vector<Vec<D>> c(n);
    for (Index i = 0; i < n; ++i)
      c[i] = boundaryArea[i] - d[i];
    return c;
  };
  double scale = 0.0;
  Vec<D> total = Vec<D>::Zero();
  for (const auto& a : boundaryArea) {
    scale = std::max(scale, a.norm());
    total += a;
  }
  if (scale == 0.0) throw SetupError("the body's boundary has no area");
  // A closed boundary's area vectors sum to zero; an open one has no consistent correction.
  if (total.norm() > 1e-8 * scale * std::sqrt(double(n)))
    throw SetupError("the body's boundary is not closed: its area vectors sum to " +
                     std::to_string(total.norm()) + ", the largest is " + std::to_string(scale));

  const auto started = std::chrono::steady_clock::now();
  IntegrationConstraintSummary& summary = ref.integrationConstraint;
  summary = {};
  summary.applied = true;
  std::vector<Vec<D>> c = defect();
  for (const auto& ci : c)
    summary.defectBefore = std::max(summary.defectBefore, ci.norm() / scale);

  const Projectors<D> projector(ref, volume);
  const PairArray<Index> rev = reversePairIndex(nb);
  PairArray<Vec<D>> y(nb.pairCount()), z(nb.pairCount());
  auto spread = [&](const Eigen::VectorXd& lambda) {  // z = Pi A^T lambda
    auto at = [&](Index i) { return Vec<D>(lambda.template segment<D>(D * i)); };
#pragma omp parallel for schedule(static)
    for (Index i = 0; i < n; ++i)
      for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k)
        y[k] = volume[i] * (at(nb.neighbour[k]) - at(i));
    projector.apply(nb, y, z);
  };
  auto gather = [&](Eigen::VectorXd& r) {  // r = A z
#pragma omp parallel for schedule(static)
    for (Index i = 0; i < n; ++i) {
      Vec<D> s = Vec<D>::Zero();
      for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k)
        s += volume[nb.neighbour[k]] * z[rev[k]] - volume[i] * z[k];
      r.template segment<D>(D * i) = s;
    }
  };
  // A Pi A^T annihilates every lambda that is a quadratic (linear on the linear correction)
  // polynomial of X: its differences are what Pi projects out. The defect's part along those
  // fields cannot be corrected; it is the quadrature error of int grad q dV against the
  // boundary sum of a_I q(X_I), O(h^2), and is left (removed from the right side).
  Eigen::VectorXd b(D * n), lambda = Eigen::VectorXd::Zero(D * n);
  {
    Vec<D> centre = Vec<D>::Zero();
    for (Index i = 0; i < n; ++i)
      centre += X[i];
    centre /= double(n);
    double radius = 0.0;
    for (Index i = 0; i < n; ++i)
      radius = std::max(radius, (X[i] - centre).norm());
    const int T = ref.correction == GradientCorrection::Quadratic ? kQuadraticTerms<D> + 1 : D + 1;
    Eigen::MatrixXd Q(n, T);
    for (Index i = 0; i < n; ++i) {
      Q(i, 0) = 1.0;
      Q.row(i).tail(T - 1) = quadraticBasis<D>((X[i] - centre) / radius).head(T - 1).transpose();
    }
    const Eigen::MatrixXd QtQ = Q.transpose() * Q;
    const Eigen::LDLT<Eigen::MatrixXd> solve(QtQ);
    for (int a = 0; a < D; ++a) {
      Eigen::VectorXd ca(n);
      for (Index i = 0; i < n; ++i)
        ca[i] = c[i][a];
      ca -= Q * solve.solve(Q.transpose() * ca);
      for (Index i = 0; i < n; ++i)
        b[D * i + a] = ca[i];
    }
  }
  // Conjugate gradients preconditioned by a Cholesky factor of B + eps diag(B), B the operator's
  // matrix for one component (the same for each): the operator is of high order in the smooth
  // fields (Pi removes their differences up to the quadratic), so a diagonal preconditioner
  // leaves the smooth part of the defect to thousands of iterations, while the factor of the
  // slightly shifted matrix leaves only its few eigenvalues below eps, a handful of iterations.
  // The best iterate is kept (the residual of a semi-definite system need not fall monotonely).
  const SparseCholesky::Matrix B = constraintMatrix<D>(nb, projector, volume);
  const Eigen::VectorXd diagonal = B.diagonal();
  SparseCholesky factor;
  {
    SparseCholesky::Matrix shifted = B;
    for (Index i = 0; i < n; ++i)
      shifted.coeffRef(i, i) += kIntegrationShift * std::max(diagonal[i], 0.0);
    summary.factorised = factor.factorise(shifted);
  }
  auto precondition = [&](const Eigen::VectorXd& r) {
    Eigen::VectorXd z(D * n);
    if (!summary.factorised) {
      for (Index q = 0; q < D * n; ++q)
        z[q] = diagonal[q / D] > 0.0 ? r[q] / diagonal[q / D] : r[q];
      return z;
    }
    Eigen::VectorXd component(n);
    for (int a = 0; a < D; ++a) {
      for (Index i = 0; i < n; ++i)
        component[i] = r[D * i + a];
      const Eigen::VectorXd solved = factor.solve(component);
      for (Index i = 0; i < n; ++i)
        z[D * i + a] = solved[i];
    }
    return z;
  };
  Eigen::VectorXd r = b, best = lambda, Ap(D * n);
  Eigen::VectorXd zr = precondition(r), p = zr;
  double rz = r.dot(zr), bestResidual = r.norm();
  const double target = kIntegrationTolerance * b.norm();
  int it = 0;
  for (; it < kIntegrationIterations && bestResidual > target; ++it) {
    spread(p);
    gather(Ap);
    const double curvature = p.dot(Ap);
    if (!(curvature > 0.0)) break;
    const double step = rz / curvature;
    lambda += step * p;
    r -= step * Ap;
    if (r.norm() < bestResidual) {
      bestResidual = r.norm();
      best = lambda;
    }
    zr = precondition(r);
    const double rzNew = r.dot(zr);
    p = zr + (rzNew / rz) * p;
    rz = rzNew;
  }
  lambda = best;
  summary.iterations = it;

  spread(lambda);
  for (Index k = 0; k < nb.pairCount(); ++k)
    ref.correctedGradient[k] += z[k];
  refreshGradientSums<D>(ref, volume);

  for (const auto& ci : defect())
    summary.defectAfter = std::max(summary.defectAfter, ci.norm() / scale);
  summary.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
}

template <int D>
ReferenceConfiguration<D> buildSceneReference(const std::vector<Vec<D>>& X,
                                              const std::vector<double>& volume,
                                              const Kernel<D>& kernel, const PeriodicBox<D>& box,
                                              GradientCorrection correction, Quadrature quadrature,
                                              const QuadratureMoments<D>& moments,
                                              const std::vector<Vec<D>>& boundaryArea,
                                              const std::vector<Index>* rows) {
  auto build = [&](const std::vector<Index>* some) {
    return buildReferenceConfiguration<D>(X, volume, kernel, box, correction,
                                          kDefaultMinCorrectionCondition, some);
  };
  if (boundaryArea.empty()) return build(rows);
  ReferenceConfiguration<D> whole = build(nullptr);
  const PairArray<Vec<D>> extra = quadrature == Quadrature::Taylor
                                      ? taylorPairVectors<D>(whole, volume, moments)
                                      : PairArray<Vec<D>>{};
  enforceIntegrationConstraint<D>(whole, X, volume, boundaryArea, extra);
  if (!rows) return whole;
  // The rows' lists are the whole build's: their corrected vectors are copied over.
  ReferenceConfiguration<D> part = build(rows);
  const auto& wn = whole.neighbours;
  const auto& pn = part.neighbours;
  for (Index i : *rows)
    for (Index k = 0; k < pn.count(i); ++k)
      part.correctedGradient[pn.offset[i] + k] = whole.correctedGradient[wn.offset[i] + k];
  refreshGradientSums<D>(part, volume);
  part.integrationConstraint = whole.integrationConstraint;
  return part;
}

template std::vector<Vec<2>> quadratureDefect<2>(const NeighbourList&, const PairArray<Vec<2>>&,
                                                 const std::vector<double>&);
template std::vector<Vec<3>> quadratureDefect<3>(const NeighbourList&, const PairArray<Vec<3>>&,
                                                 const std::vector<double>&);
template PairArray<Vec<2>> taylorPairVectors<2>(const ReferenceConfiguration<2>&,
                                                const std::vector<double>&,
                                                const QuadratureMoments<2>&);
template PairArray<Vec<3>> taylorPairVectors<3>(const ReferenceConfiguration<3>&,
                                                const std::vector<double>&,
                                                const QuadratureMoments<3>&);
template void enforceIntegrationConstraint<2>(ReferenceConfiguration<2>&,
                                              const std::vector<Vec<2>>&,
                                              const std::vector<double>&,
                                              const std::vector<Vec<2>>&, const PairArray<Vec<2>>&);
template void enforceIntegrationConstraint<3>(ReferenceConfiguration<3>&,
                                              const std::vector<Vec<3>>&,
                                              const std::vector<double>&,
                                              const std::vector<Vec<3>>&, const PairArray<Vec<3>>&);
template ReferenceConfiguration<2> buildSceneReference<2>(
    const std::vector<Vec<2>>&, const std::vector<double>&, const Kernel<2>&, const PeriodicBox<2>&,
    GradientCorrection, Quadrature, const QuadratureMoments<2>&, const std::vector<Vec<2>>&,
    const std::vector<Index>*);
template ReferenceConfiguration<3> buildSceneReference<3>(
    const std::vector<Vec<3>>&, const std::vector<double>&, const Kernel<3>&, const PeriodicBox<3>&,
    GradientCorrection, Quadrature, const QuadratureMoments<3>&, const std::vector<Vec<3>>&,
    const std::vector<Index>*);

}  // namespace tlsph
