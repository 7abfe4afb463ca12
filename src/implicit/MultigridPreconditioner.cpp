// MultigridPreconditioner (see the header), compiled once for 2D and 3D.
#include "implicit/MultigridPreconditioner.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <sstream>

#include "implicit/MlsInterpolation.hpp"

namespace tlsph {

template <int D>
struct MultigridPreconditioner<D>::Level {
  // Coarse levels own their scene, its solver (for F at a displacement), unknowns and tangent.
  std::unique_ptr<Scene<D>> scene;
  std::unique_ptr<Solver<D>> solver;
  std::unique_ptr<DofMap<D>> ownDofs;
  std::unique_ptr<TangentStiffness<D>> ownTangent;
  const DofMap<D>* dofs = nullptr;
  TangentStiffness<D>* tangent = nullptr;
  // Next coarser level's unknowns -> this level's (one value per unknown; applied per component).
  InterpolationMatrix prolongation, restriction;
  // Coarse levels: the fine scene's particle displacements -> this level's free particles.
  InterpolationMatrix fromFine;
  std::vector<Mat<D>> diagonalInverse;
  double lambdaMax = 0.0;
  Eigen::VectorXd product;

  Index size() const { return D * dofs->size(); }
  void apply(const Eigen::VectorXd& v, Eigen::VectorXd& Kv) { tangent->apply(v, Kv); }
  Eigen::VectorXd jacobi(const Eigen::VectorXd& r) const {
    Eigen::VectorXd z(r.size());
    const Index n = dofs->size();
    for (Index p = 0; p < n; ++p)
      z.template segment<D>(D * p) = diagonalInverse[p] * r.template segment<D>(D * p);
    return z;
  }
};

namespace {

// W (targets x particles) times the unknowns' expansion of `dofs`: targets x unknowns.
template <int D>
InterpolationMatrix onUnknowns(const InterpolationMatrix& W, const DofMap<D>& dofs) {
  std::vector<Eigen::Triplet<double, Index>> entries;
  for (Index t = 0; t < W.outerSize(); ++t)
    for (InterpolationMatrix::InnerIterator it(W, t); it; ++it) {
      auto [term, end] = dofs.terms(it.col());
      for (; term != end; ++term)
        entries.emplace_back(t, term->dof, it.value() * term->weight);
    }
  InterpolationMatrix P(W.rows(), dofs.size());
  P.setFromTriplets(entries.begin(), entries.end());
  return P;
}

// y = A x for vectors of D values per row/column of the scalar interpolation A.
template <int D>
Eigen::VectorXd perComponent(const InterpolationMatrix& A, const Eigen::VectorXd& x) {
  Eigen::VectorXd y(D * A.rows());
  Eigen::Map<const Eigen::Matrix<double, D, Eigen::Dynamic>> X(x.data(), D, A.cols());
  Eigen::Map<Eigen::Matrix<double, D, Eigen::Dynamic>> Y(y.data(), D, A.rows());
  Y.transpose() = A * X.transpose();
  return y;
}

template <int D>
std::vector<Vec<D>> positionsOf(const ParticleSet<D>& p, const std::vector<Index>& which) {
  std::vector<Vec<D>> X;
  X.reserve(which.size());
  for (Index i : which)
    X.push_back(p.referencePosition[i]);
  return X;
}

}  // namespace

template <int D>
MultigridPreconditioner<D>::MultigridPreconditioner(const Scene<D>& fine, const DofMap<D>& fineDofs,
                                                    TangentStiffness<D>& fineTangent,
                                                    std::vector<std::unique_ptr<Scene<D>>> coarse,
                                                    const SolverSettings& settings) {
  if (coarse.empty()) throw SetupError("multigrid: no coarser level");
  auto top = std::make_unique<Level>();
  top->dofs = &fineDofs;
  top->tangent = &fineTangent;
  levels_.push_back(std::move(top));
  for (auto& scene : coarse) {
    auto level = std::make_unique<Level>();
    level->scene = std::move(scene);
    Scene<D>& s = *level->scene;
    // A level too coarse for the geometry (a correction tensor singular through a thin body):
    // the levels above it serve; none at all is the caller's to handle.
    try {
      level->solver = std::make_unique<Solver<D>>(s, settings);
    } catch (const SetupError& e) {
      if (levels_.size() == 1)
        throw SetupError(std::string("the scene at twice its particle spacing: ") + e.what());
      break;
    }
    level->ownDofs = std::make_unique<DofMap<D>>(s.particles, s.mirrorGhosts);
    level->dofs = level->ownDofs.get();
    level->ownTangent = std::make_unique<TangentStiffness<D>>(
        level->solver->reference(), s.materials, s.particles.material, s.particles.volume,
        s.hourglass(), *level->dofs, s.quadrature, s.particles.quadratureMoments());
    level->tangent = level->ownTangent.get();
    if (level->dofs->size() == 0) throw SetupError("multigrid: a coarse level has no unknowns");
    const Kernel<D> kernel(s.kernel, s.supportRadius);
    const std::vector<Vec<D>> X = positionsOf(s.particles, level->dofs->freeParticles());
    level->fromFine =
        mlsInterpolation<D>(X, fine.particles.referencePosition, kernel, fine.periodicBox);
    // The level above interpolates from this one's particles.
    Level& above = *levels_.back();
    const ParticleSet<D>& abovePositions =
        levels_.size() == 1 ? fine.particles : above.scene->particles;
    const InterpolationMatrix W =
        mlsInterpolation<D>(positionsOf(abovePositions, above.dofs->freeParticles()),
                            s.particles.referencePosition, kernel, s.periodicBox);
    above.prolongation = onUnknowns(W, *level->dofs);
    above.restriction = above.prolongation.transpose();
    levels_.push_back(std::move(level));
  }
  if (heldByNothing(*levels_.back()->scene)) coarsestRigid_.emplace();
}

template <int D>
MultigridPreconditioner<D>::~MultigridPreconditioner() = default;

template <int D>
bool MultigridPreconditioner<D>::update(double t, const std::vector<Vec<D>>& u, std::string& why) {
  Eigen::Map<const Eigen::Matrix<double, D, Eigen::Dynamic>> U(u.data()->data(), D,
                                                               static_cast<Index>(u.size()));
  for (std::size_t l = 1; l < levels_.size(); ++l) {
    Level& level = *levels_[l];
    Solver<D>& solver = *level.solver;
    solver.beginStaticStep(t);  // prescribed motions and mirrored faces at t
    const Eigen::Matrix<double, Eigen::Dynamic, D> Uc = level.fromFine * U.transpose();
    const auto& free = level.dofs->freeParticles();
    for (std::size_t d = 0; d < free.size(); ++d)
      level.scene->particles.displacement[free[d]] = Uc.row(static_cast<Index>(d)).transpose();
    solver.reevaluate();
    const auto& F = solver.forces().deformationGradient();
    level.tangent->update(F);
    level.tangent->updateQuadrature(solver.forces().quadrature(), F);
  }
  for (std::size_t l = 0; l + 1 < levels_.size(); ++l) {
    Level& level = *levels_[l];
    const std::vector<Mat<D>> blocks = level.tangent->diagonalBlocks();
    level.diagonalInverse.resize(blocks.size());
    for (std::size_t p = 0; p < blocks.size(); ++p) {
      const Eigen::LLT<Mat<D>> llt(blocks[p]);
      if (llt.info() != Eigen::Success) {
        std::ostringstream msg;
        msg << "the tangent stiffness has a diagonal block that is not positive definite (level "
            << l << ", unknown " << p
            << "): a material instability, or a body not held against rigid motion";
        why = msg.str();
        return false;
      }
      level.diagonalInverse[p] = llt.solve(Mat<D>::Identity());
    }
    level.lambdaMax = largestEigenvalue(level);
  }
  const Level& coarsest = *levels_.back();
  const auto& K = coarsest.tangent->assemble();
  coarsestNonZeros_ = K.nonZeros();
  if (coarsestRigid_) {
    const auto& cp = coarsest.scene->particles;
    coarsestRigid_->update(coarsest.dofs->freeParticles(), cp.referencePosition, cp.displacement);
  }
  if (!factor_.factorise(coarsestRigid_ ? shiftDiagonal(K) : K)) {
    why =
        "the coarsest multigrid level's tangent stiffness is not positive definite (a buckling "
        "or material instability, or a body not held against rigid motion)";
    return false;
  }
  return true;
}

// Lanczos through conjugate gradients on K x = b preconditioned by D^-1: the tridiagonal matrix
// of the CG coefficients has the Ritz values of D^-1 K, the largest of which converges from
// below within a few steps. A fixed start vector keeps runs reproducible.
template <int D>
double MultigridPreconditioner<D>::largestEigenvalue(Level& level) {
  constexpr int kSteps = 12;
  const Index n = level.size();
  Eigen::VectorXd r(n), Ap(n);
  for (Index i = 0; i < n; ++i)
    r[i] = std::sin(12.9898 * static_cast<double>(i) + 78.233);
  Eigen::VectorXd z = level.jacobi(r), p = z;
  double rz = r.dot(z);
  std::vector<double> alpha, beta;
  for (int k = 0; k < kSteps && rz > 0.0; ++k) {
    level.apply(p, Ap);
    const double pAp = p.dot(Ap);
    if (!(pAp > 0.0)) break;
    alpha.push_back(rz / pAp);
    r -= alpha.back() * Ap;
    z = level.jacobi(r);
    const double rzNew = r.dot(z);
    beta.push_back(rzNew / rz);
    rz = rzNew;
    p = z + beta.back() * p;
  }
  const int m = static_cast<int>(alpha.size());
  if (m == 0) return 1.0;
  Eigen::MatrixXd T = Eigen::MatrixXd::Zero(m, m);
  for (int j = 0; j < m; ++j) {
    T(j, j) = 1.0 / alpha[j] + (j > 0 ? beta[j - 1] / alpha[j - 1] : 0.0);
    if (j + 1 < m) T(j, j + 1) = T(j + 1, j) = std::sqrt(beta[j]) / alpha[j];
  }
  // The largest Ritz value lies below the largest eigenvalue: a margin keeps the top of the
  // spectrum inside the Chebyshev interval, where the smoother damps instead of amplifying.
  return 1.1 * Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(T).eigenvalues().maxCoeff();
}

// Chebyshev iteration of degree kSmootherDegree on K x = r from x = 0, preconditioned by D^-1:
// x = q(D^-1 K) D^-1 r, a symmetric operator (q a polynomial).
template <int D>
Eigen::VectorXd MultigridPreconditioner<D>::smooth(Level& level, const Eigen::VectorXd& r) {
  const double upper = level.lambdaMax, lower = upper / kSmoothedRatio;
  const double theta = 0.5 * (upper + lower), delta = 0.5 * (upper - lower);
  const double sigma = theta / delta;
  double rho = 1.0 / sigma;
  Eigen::VectorXd d = level.jacobi(r) / theta;
  Eigen::VectorXd x = d;
  for (int k = 1; k < kSmootherDegree; ++k) {
    level.apply(x, level.product);
    const double next = 1.0 / (2.0 * sigma - rho);
    d = (next * rho) * d + (2.0 * next / delta) * level.jacobi(r - level.product);
    x += d;
    rho = next;
  }
  return x;
}

template <int D>
Eigen::VectorXd MultigridPreconditioner<D>::cycle(std::size_t l, const Eigen::VectorXd& r) {
  if (l + 1 == levels_.size()) {
    Eigen::VectorXd z = factor_.solve(r);
    if (coarsestRigid_) coarsestRigid_->project(z);
    return z;
  }
  Level& level = *levels_[l];
  Eigen::VectorXd x = smooth(level, r);
  level.apply(x, level.product);
  x += perComponent<D>(level.prolongation,
                       cycle(l + 1, perComponent<D>(level.restriction, r - level.product)));
  level.apply(x, level.product);
  x += smooth(level, r - level.product);
  return x;
}

template <int D>
Eigen::VectorXd MultigridPreconditioner<D>::apply(const Eigen::VectorXd& r) {
  return cycle(0, r);
}

template <int D>
std::vector<Index> MultigridPreconditioner<D>::unknowns() const {
  std::vector<Index> n;
  for (const auto& level : levels_)
    n.push_back(level->size());
  return n;
}

template <int D>
std::string MultigridPreconditioner<D>::description() const {
  std::ostringstream s;
  s << levels_.size() << "-level multigrid (";
  const auto n = unknowns();
  for (std::size_t l = 0; l < n.size(); ++l)
    s << (l ? " / " : "") << n[l];
  s << " unknowns; Chebyshev-block-Jacobi smoothing, " << SparseCholesky::name()
    << " on the coarsest)";
  return s.str();
}

template class MultigridPreconditioner<2>;
template class MultigridPreconditioner<3>;

}  // namespace tlsph
