// The integration constraint's correction of the gradient vectors (IntegrationConstraint.hpp),
// compiled once for 2D and 3D: a set-up cost, one preconditioned conjugate-gradient solve per body.
#include "method/IntegrationConstraint.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <tuple>

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
// The linear-stress constraint's solve: the residual falls below this fraction of the right
// side, or the iterations run out.
constexpr double kLinearConstraintTolerance = 1e-8;
constexpr int kLinearConstraintIterations = 20000;

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

// The particles' centroid and their largest distance from it: the scale of the polynomial
// null spaces' monomials.
template <int D>
std::pair<Vec<D>, double> boundingSphere(const std::vector<Vec<D>>& X) {
  Vec<D> centre = Vec<D>::Zero();
  for (const auto& x : X)
    centre += x;
  centre /= double(X.size());
  double radius = 0.0;
  for (const auto& x : X)
    radius = std::max(radius, (x - centre).norm());
  return {centre, radius};
}

// The largest |a_I|, after checking that there is one a_I per particle and that they describe a
// closed boundary (their sum vanishes; an open one has no consistent correction).
template <int D>
double checkedBoundaryScale(const std::vector<Vec<D>>& boundaryArea, Index n) {
  if (static_cast<Index>(boundaryArea.size()) != n)
    throw SetupError("the boundary's area vectors are not one per particle");
  double scale = 0.0;
  Vec<D> total = Vec<D>::Zero();
  for (const auto& a : boundaryArea) {
    scale = std::max(scale, a.norm());
    total += a;
  }
  if (scale == 0.0) throw SetupError("the body's boundary has no area");
  if (total.norm() > 1e-8 * scale * std::sqrt(double(n)))
    throw SetupError("the body's boundary is not closed: its area vectors sum to " +
                     std::to_string(total.norm()) + ", the largest is " + std::to_string(scale));
  return scale;
}

}  // namespace

template <int D>
void enforceIntegrationConstraint(ReferenceConfiguration<D>& ref, const std::vector<Vec<D>>& X,
                                  const std::vector<double>& volume,
                                  const std::vector<Vec<D>>& boundaryArea,
                                  const PairArray<Vec<D>>& extra) {
  const auto& nb = ref.neighbours;
  const Index n = ref.particleCount();
  const double scale = checkedBoundaryScale<D>(boundaryArea, n);
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
    const auto [centre, radius] = boundingSphere<D>(X);
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
void enforceLinearStressConstraint(ReferenceConfiguration<D>& ref, const std::vector<Vec<D>>& X,
                                   const std::vector<double>& volume,
                                   const std::vector<Vec<D>>& boundaryArea,
                                   const std::vector<Mat<D>>& boundaryMoment, double filter,
                                   const PairArray<Vec<D>>& extra) {
  constexpr int U = 1 + D;        // multipliers per particle and component: lambda, then Lambda
  using Field = Eigen::MatrixXd;  // (U n) x D: particle I's rows U I .. U I + D, a column each
  const auto& nb = ref.neighbours;
  const Index n = ref.particleCount();
  const double scale = checkedBoundaryScale<D>(boundaryArea, n);
  if (static_cast<Index>(boundaryMoment.size()) != n)
    throw SetupError("the boundary's first moments are not one per particle");
  if (!(filter > 0.0)) throw SetupError("the linear-stress constraint needs a positive filter");
  const auto started = std::chrono::steady_clock::now();
  IntegrationConstraintSummary& summary = ref.integrationConstraint;
  summary = {};
  summary.applied = summary.linear = summary.factorised = true;
  summary.filter = filter;

  const PairArray<Index> rev = reversePairIndex(nb);
  // The defects c_I = a_I - d_I and e_I = b_I - V_I 1 - m_I of the vectors g + extra.
  std::vector<Vec<D>> c(n);
  std::vector<Mat<D>> e(n);
  auto defects = [&]() {
    PairArray<Vec<D>> v = ref.correctedGradient;
    if (!extra.empty())
      for (Index k = 0; k < nb.pairCount(); ++k)
        v[k] += extra[k];
    const std::vector<Vec<D>> d = quadratureDefect<D>(nb, v, volume);
#pragma omp parallel for schedule(static)
    for (Index I = 0; I < n; ++I) {
      Mat<D> m = Mat<D>::Zero();
      for (Index k = nb.offset[I]; k < nb.offset[I + 1]; ++k) {
        const Index J = nb.neighbour[k];
        // I's moment from the pair (J, I): V_J (X_J - X_I) (x) v_JI
        m.noalias() += volume[J] * (X[J] - X[I]) * v[rev[k]].transpose();
      }
      c[I] = boundaryArea[I] - d[I];
      e[I] = boundaryMoment[I] - volume[I] * Mat<D>::Identity() - m;
    }
    double cMax = 0.0, eMax = 0.0;
    for (Index I = 0; I < n; ++I) {
      cMax = std::max(cMax, c[I].norm() / scale);
      eMax = std::max(eMax, e[I].norm() / volume[I]);
    }
    return std::pair<double, double>(cMax, eMax);
  };
  std::tie(summary.defectBefore, summary.momentDefectBefore) = defects();

  const Projectors<D> projector(ref, volume);
  // Lambda in units of lambda per length: scaled by the mean pair distance, so that both kinds of
  // multiplier weigh alike in the solve and in the null space's bar.
  double meanDistance = 0.0;
  for (Index k = 0; k < nb.pairCount(); ++k)
    meanDistance += ref.separation[k].norm();
  const double ls = double(nb.pairCount()) / meanDistance;

  PairArray<Vec<D>> y(nb.pairCount()), z(nb.pairCount());
  auto spread = [&](const Field& mu) {  // z = Pi A^T mu
#pragma omp parallel for schedule(static)
    for (Index K = 0; K < n; ++K)
      for (Index k = nb.offset[K]; k < nb.offset[K + 1]; ++k) {
        const Index J = nb.neighbour[k];
        Vec<D> s = (mu.row(U * J) - mu.row(U * K)).transpose();
        s.noalias() += ls * mu.block(U * J + 1, 0, D, D).transpose() * (X[K] - X[J]);
        y[k] = volume[K] * s;
      }
    projector.apply(nb, y, z);
  };
  auto gather = [&](Field& out) {  // out = A z
#pragma omp parallel for schedule(static)
    for (Index I = 0; I < n; ++I) {
      Vec<D> toLambda = Vec<D>::Zero();
      Mat<D> toMoment = Mat<D>::Zero();
      for (Index k = nb.offset[I]; k < nb.offset[I + 1]; ++k) {
        const Index J = nb.neighbour[k], r = rev[k];
        toLambda += volume[J] * z[r] - volume[I] * z[k];
        toMoment.noalias() += (ls * volume[J]) * (X[J] - X[I]) * z[r].transpose();
      }
      for (int j = 0; j < D; ++j) {  // (element by element: GCC 12 misreads Eigen's packets here)
        out(U * I, j) = toLambda[j];
        for (int a = 0; a < D; ++a)
          out(U * I + 1 + a, j) = toMoment(a, j);
      }
    }
  };
  auto applyB = [&](const Field& mu, Field& out) {
    spread(mu);
    gather(out);
  };
  // Lambda's diagonal blocks of B (the same for every component): particle I's multipliers reach
  // the pairs (K, I) of its neighbours K, one pair value each, V_K (1, ls (X_K - X_I)).
  std::vector<Mat<D>> momentBlock(n, Mat<D>::Zero());
  Eigen::VectorXd momentDiagonal(D * n);
#pragma omp parallel for schedule(static)
  for (Index I = 0; I < n; ++I) {
    for (Index k = nb.offset[I]; k < nb.offset[I + 1]; ++k) {
      const Index K = nb.neighbour[k], r = rev[k];
      const double w = projector.weight[r];
      const double pi =
          w - w * w * projector.basis[r].dot(projector.inverse[K] * projector.basis[r]);
      const Vec<D> t = ls * (X[K] - X[I]);
      momentBlock[I] += (volume[K] * volume[K] * pi) * t * t.transpose();
    }
    momentDiagonal.template segment<D>(D * I) = momentBlock[I].diagonal();
  }

  // The preconditioner: lambda's block by the factor of the uniform constraint's matrix (shifted as
  // there), each particle's Lambda block with the filter's shift by its inverse.
  SparseCholesky factor;
  double lambdaLargest = 0.0;  // lambda's largest diagonal entry
  {
    SparseCholesky::Matrix B = constraintMatrix<D>(nb, projector, volume);
    const Eigen::VectorXd diagonal = B.diagonal();
    lambdaLargest = diagonal.maxCoeff();
    for (Index i = 0; i < n; ++i)
      B.coeffRef(i, i) += kIntegrationShift * std::max(diagonal[i], 0.0);
    if (!factor.factorise(B))
      throw SetupError("the integration constraint's matrix could not be factorised");
  }
  // The null space: B on the span of lambda cubic and Lambda quadratic (monomials of the
  // positions scaled to the body), its eigenvectors below 1e-10 of the largest diagonal (they
  // sit at 1e-17; the next eigenvalue at 1e-6).
  Field Q;
  {
    const auto [centre, radius] = boundingSphere<D>(X);
    std::vector<std::array<int, 3>> powers;
    for (int a = 0; a <= 3; ++a)
      for (int b = 0; b <= 3 - a; ++b)
        for (int g = 0; g <= (D == 3 ? 3 - a - b : 0); ++g)
          powers.push_back({a, b, g});
    auto monomial = [&](const std::array<int, 3>& p, Index i) {
      const Vec<D> x = (X[i] - centre) / radius;
      double v = 1.0;
      for (int a = 0; a < D; ++a)
        for (int q = 0; q < p[a]; ++q)
          v *= x[a];
      return v;
    };
    std::vector<std::pair<int, std::array<int, 3>>> columns;  // (slot, powers)
    for (const auto& p : powers)
      columns.push_back({0, p});
    for (int a = 0; a < D; ++a)
      for (const auto& p : powers)
        if (p[0] + p[1] + p[2] <= 2) columns.push_back({1 + a, p});
    const int m = int(columns.size());
    Field P = Field::Zero(U * n, m);
    for (int q = 0; q < m; ++q)
      for (Index i = 0; i < n; ++i)
        P(U * i + columns[q].first, q) = monomial(columns[q].second, i);
    const Eigen::HouseholderQR<Field> qr(P);
    const Field basis = qr.householderQ() * Field::Identity(U * n, m);
    Field Bbasis(U * n, m), in(U * n, D), out(U * n, D);
    for (int q0 = 0; q0 < m; q0 += D) {
      in.setZero();
      for (int j = 0; j < D && q0 + j < m; ++j)
        in.col(j) = basis.col(q0 + j);
      applyB(in, out);
      for (int j = 0; j < D && q0 + j < m; ++j)
        Bbasis.col(q0 + j) = out.col(j);
    }
    Field H = basis.transpose() * Bbasis;
    H = (0.5 * (H + H.transpose())).eval();
    const Eigen::SelfAdjointEigenSolver<Field> eigen(H);
    const double largest = std::max(lambdaLargest, momentDiagonal.maxCoeff());
    int null = 0;
    while (null < m && eigen.eigenvalues()[null] < 1e-10 * largest)
      ++null;
    Q = basis * eigen.eigenvectors().leftCols(null);
  }
  auto project = [&](Field& v) { v -= Q * (Q.transpose() * v); };

  std::vector<Mat<D>> momentInverse(n);
  for (Index I = 0; I < n; ++I) {
    Mat<D> s = momentBlock[I];
    s.diagonal() *= 1.0 + filter;
    // a pseudo-inverse: a particle whose neighbours all lie on one line or plane has a
    // singular block
    const Eigen::SelfAdjointEigenSolver<Mat<D>> eigen(s);
    const double floor = 1e-12 * std::max(eigen.eigenvalues().maxCoeff(), 0.0);
    Vec<D> inverse = Vec<D>::Zero();
    for (int a = 0; a < D; ++a)
      if (eigen.eigenvalues()[a] > floor) inverse[a] = 1.0 / eigen.eigenvalues()[a];
    momentInverse[I] =
        eigen.eigenvectors() * inverse.asDiagonal() * eigen.eigenvectors().transpose();
  }
  auto precondition = [&](const Field& r, Field& out) {
    Eigen::VectorXd component(n);
    for (int j = 0; j < D; ++j) {
      for (Index I = 0; I < n; ++I)
        component[I] = r(U * I, j);
      const Eigen::VectorXd solved = factor.solve(component);
      for (Index I = 0; I < n; ++I)
        out(U * I, j) = solved[I];
    }
#pragma omp parallel for schedule(static)
    for (Index I = 0; I < n; ++I)
      out.block(U * I + 1, 0, D, D) = momentInverse[I] * r.block(U * I + 1, 0, D, D);
    project(out);
  };
  auto applyFiltered = [&](const Field& mu, Field& out) {
    applyB(mu, out);
#pragma omp parallel for schedule(static)
    for (Index I = 0; I < n; ++I)
      out.block(U * I + 1, 0, D, D) += filter *
                                       momentDiagonal.template segment<D>(D * I).asDiagonal() *
                                       mu.block(U * I + 1, 0, D, D);
  };

  Field b(U * n, D);
  for (Index I = 0; I < n; ++I) {
    b.row(U * I) = c[I].transpose();
    b.block(U * I + 1, 0, D, D) = ls * e[I];
  }
  project(b);
  // Conjugate gradients, one per component, run side by side.
  const Eigen::VectorXd target = kLinearConstraintTolerance * b.colwise().norm().transpose();
  Field mu = Field::Zero(U * n, D), r = b, s(U * n, D), p(U * n, D), Ap(U * n, D);
  precondition(r, s);
  p = s;
  Eigen::VectorXd rs = r.cwiseProduct(s).colwise().sum().transpose();
  auto converged = [&](int j) { return r.col(j).norm() <= target[j]; };
  int it = 0;
  for (; it < kLinearConstraintIterations; ++it) {
    bool done = true;
    for (int j = 0; j < D; ++j)
      done = done && converged(j);
    if (done) break;
    applyFiltered(p, Ap);
    for (int j = 0; j < D; ++j) {
      if (converged(j)) continue;
      const double step = rs[j] / p.col(j).dot(Ap.col(j));
      mu.col(j) += step * p.col(j);
      r.col(j) -= step * Ap.col(j);
    }
    project(r);
    precondition(r, s);
    for (int j = 0; j < D; ++j) {
      if (converged(j)) continue;
      const double rsNew = r.col(j).dot(s.col(j));
      p.col(j) = s.col(j) + (rsNew / rs[j]) * p.col(j);
      rs[j] = rsNew;
    }
  }
  summary.iterations = it;
  project(mu);
  spread(mu);
  double corrected = 0.0, original = 0.0;
  for (Index k = 0; k < nb.pairCount(); ++k) {
    corrected += z[k].squaredNorm();
    original += ref.correctedGradient[k].squaredNorm();
    ref.correctedGradient[k] += z[k];
  }
  summary.correction = std::sqrt(corrected / original);
  refreshGradientSums<D>(ref, volume);
  std::tie(summary.defectAfter, summary.momentDefectAfter) = defects();
  summary.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
}

template <int D>
ReferenceConfiguration<D> buildSceneReference(
    const std::vector<Vec<D>>& X, const std::vector<double>& volume, const Kernel<D>& kernel,
    const PeriodicBox<D>& box, GradientCorrection correction, Quadrature quadrature,
    const QuadratureMoments<D>& moments, const std::vector<Vec<D>>& boundaryArea,
    const std::vector<Mat<D>>& boundaryMoment, double filter, const std::vector<Index>* rows) {
  auto build = [&](const std::vector<Index>* some) {
    return buildReferenceConfiguration<D>(X, volume, kernel, box, correction,
                                          kDefaultMinCorrectionCondition, some);
  };
  if (boundaryArea.empty()) return build(rows);
  ReferenceConfiguration<D> whole = build(nullptr);
  const PairArray<Vec<D>> extra = quadrature == Quadrature::Taylor
                                      ? taylorPairVectors<D>(whole, volume, moments)
                                      : PairArray<Vec<D>>{};
  if (boundaryMoment.empty())
    enforceIntegrationConstraint<D>(whole, X, volume, boundaryArea, extra);
  else
    enforceLinearStressConstraint<D>(whole, X, volume, boundaryArea, boundaryMoment, filter, extra);
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
    const std::vector<Mat<2>>&, double, const std::vector<Index>*);
template void enforceLinearStressConstraint<2>(
    ReferenceConfiguration<2>&, const std::vector<Vec<2>>&, const std::vector<double>&,
    const std::vector<Vec<2>>&, const std::vector<Mat<2>>&, double, const PairArray<Vec<2>>&);
template ReferenceConfiguration<3> buildSceneReference<3>(
    const std::vector<Vec<3>>&, const std::vector<double>&, const Kernel<3>&, const PeriodicBox<3>&,
    GradientCorrection, Quadrature, const QuadratureMoments<3>&, const std::vector<Vec<3>>&,
    const std::vector<Mat<3>>&, double, const std::vector<Index>*);
template void enforceLinearStressConstraint<3>(
    ReferenceConfiguration<3>&, const std::vector<Vec<3>>&, const std::vector<double>&,
    const std::vector<Vec<3>>&, const std::vector<Mat<3>>&, double, const PairArray<Vec<3>>&);

}  // namespace tlsph
