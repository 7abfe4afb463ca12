// NewtonSolver (see the header), compiled once for 2D and 3D.
#include "implicit/NewtonSolver.hpp"

#include <algorithm>

#include "implicit/BiCgStab.hpp"
#include "implicit/ConjugateGradients.hpp"

namespace tlsph {

template <int D>
NewtonSolver<D>::NewtonSolver(Scene<D>& scene, Solver<D>& solver, const NewtonSettings& settings,
                              const SceneCoarsening<D>& coarsen,
                              const SolverSettings& solverSettings)
    : scene_(scene),
      solver_(solver),
      settings_(settings),
      dofs_(scene.particles, scene.mirrorGhosts),
      tangent_(solver.reference(), scene.materials, scene.particles.material,
               scene.particles.volume, scene.hourglass(), dofs_, scene.quadrature,
               scene.particles.quadratureMoments()) {
  if (settings.loadSteps < 1) throw SetupError("[static] load_steps must be at least 1");
  const Index unknowns = D * dofs_.size();
  const bool explicitly = settings.preconditioner == NewtonPreconditioner::Multigrid;
  // Block-Jacobi smoothing cannot reach the volumetric modes of a nearly incompressible body
  // (Cook's membrane at nu = 0.4999: the conjugate gradients stall), a direct factor can.
  double poisson = 0.0;
  for (const Material& m : scene.materials) {
    const auto c = elasticConstants(m);
    poisson = std::max(poisson, c.lambda / (2.0 * (c.lambda + c.mu)));
  }
  const bool wanted = explicitly || (settings.preconditioner == NewtonPreconditioner::Auto &&
                                     unknowns >= settings.autoMultigridUnknowns &&
                                     poisson < settings.autoPoissonLimit && coarsen);
  if (wanted) {
    if (!coarsen)
      throw SetupError("[static] preconditioner = multigrid needs the scene rebuilt coarser");
    // Levels at 2, 4, ... times the spacing while they still shrink, down to a cheap factor.
    std::vector<std::unique_ptr<Scene<D>>> coarse;
    Index last = unknowns;
    for (int factor = 2; (coarse.empty() || last > kCoarsestUnknowns) && factor <= 64;
         factor *= 2) {
      std::unique_ptr<Scene<D>> s = coarsen(factor);
      if (!s) break;
      Index free = 0;
      for (Motion m : s->particles.motion)
        free += m == Motion::Free;
      if (free == 0 || 2 * D * free > last) break;  // no coarser (points from a file, say)
      last = D * free;
      coarse.push_back(std::move(s));
    }
    if (coarse.empty()) {
      if (explicitly)
        throw SetupError(
            "[static] preconditioner = multigrid: the scene cannot be rebuilt at twice its "
            "particle spacing with fewer unknowns (use preconditioner = cholesky)");
    } else {
      try {
        multigrid_ = std::make_unique<MultigridPreconditioner<D>>(
            scene, dofs_, tangent_, std::move(coarse), solverSettings);
        statistics_.levels = multigrid_->levelCount();
      } catch (const SetupError& e) {
        if (explicitly)
          throw SetupError(std::string("[static] preconditioner = multigrid: ") + e.what() +
                           " (use preconditioner = cholesky)");
      }
    }
  }
  if (heldByNothing(scene)) {
    rigid_.emplace();
    solver.leaveOutRigidPart();
  }
  for (const auto& load : scene.loads)
    following_ = following_ || load.following.has_value();
  if (following_) {
    variation_.resize(scene.particles.size());
    loadProduct_.resize(scene.particles.size());
  }
  statistics_.linearSolver = multigrid_ ? multigrid_->description() : SparseCholesky::name();
  if (multigrid_ || !tangent_.assemblyExact() || following_)
    statistics_.linearSolver =
        std::string(krylovName()) + " preconditioned by " + statistics_.linearSolver;
}

template <int D>
NewtonSolver<D>::~NewtonSolver() = default;

template <int D>
void NewtonSolver<D>::useCholesky(const std::string& why) {
  multigrid_.reset();
  factorised_ = false;
  statistics_.levels = 1;
  statistics_.linearSolver = std::string(krylovName()) + " preconditioned by " +
                             SparseCholesky::name() + " (multigrid given up: " + why + ")";
}

template <int D>
void NewtonSolver<D>::run(const std::function<bool()>& onStep) {
  const double end = solver_.rampEnd();
  if (!resumed_) {
    done_ = 0.0;
    increment_ = end > 0.0 ? end / settings_.loadSteps : 0.0;
    cuts_ = 0;
    started_ = false;
  }
  resumed_ = false;
  while (!started_ || done_ < end * (1.0 - 1e-12)) {
    const double target = end > 0.0 ? std::min(end, done_ + increment_) : 0.0;
    std::string why;
    if (solveAt(target, why)) {
      solver_.finishStaticStep();
      ++statistics_.loadSteps;
      done_ = target;
      started_ = true;
      if (!onStep()) return;
      continue;
    }
    solver_.abandonStaticStep();  // back to the last converged state
    if (end <= 0.0 || ++cuts_ > settings_.maxCuts) {
      std::ostringstream msg;
      msg << "Newton solver: no equilibrium at load time t = " << target << " s";
      if (end > 0.0) msg << " (" << 100.0 * target / end << " % of the load)";
      msg << ": " << why << ". The output holds the last converged state (t = " << done_
          << " s). Try more load steps ([static] load_steps)"
          << (multigrid_ ? ", [static] preconditioner = cholesky" : "") << ", or solver = damped.";
      throw NewtonFailure(msg.str());
    }
    increment_ *= 0.5;
  }
}

template <int D>
NewtonState<D> NewtonSolver<D>::state() const {
  NewtonState<D> s;
  s.done = done_;
  s.increment = increment_;
  s.cuts = cuts_;
  s.started = started_;
  s.factorised = factorised_;
  s.lastKrylov = lastKrylov_;
  s.lastStep = lastStep_;
  s.statistics = statistics_;
  if (factorised_) {
    s.factorDeformation = factorDeformation_;
    if (multigrid_) {
      s.factorTime = factorTime_;
      s.factorDisplacement = factorDisplacement_;
      s.factorSecondGradients = factorSecondGradients_;
    }
  }
  return s;
}

template <int D>
void NewtonSolver<D>::resume(const NewtonState<D>& s) {
  done_ = s.done;
  increment_ = s.increment;
  cuts_ = s.cuts;
  started_ = s.started;
  lastKrylov_ = s.lastKrylov;
  lastStep_ = s.lastStep;
  factorised_ = false;
  // The interrupted run had given up its multigrid: so does this one.
  if (multigrid_ && s.statistics.levels == 1) useCholesky("as before the restart");
  if (s.factorised) {
    // The same matrix as before the stop: the tangent at the saved F, factorised again.
    if (s.factorDeformation.size() != scene_.particles.displacement.size())
      throw SetupError("the saved Newton state does not fit the scene (particle count)");
    tangent_.update(s.factorDeformation);
    std::string why;
    if (multigrid_) {
      tangent_.updateQuadrature(s.factorSecondGradients, s.factorDeformation);
      if (s.factorDisplacement.size() != scene_.particles.displacement.size() ||
          !updateMultigrid(s.factorTime, s.factorDisplacement, s.factorDeformation,
                           s.factorSecondGradients, why))
        throw NewtonFailure("Newton solver: on restart, the multigrid preconditioner: " +
                            (why.empty() ? std::string("the saved state does not fit") : why));
    } else if (!factorise(why)) {
      throw NewtonFailure("Newton solver: on restart, " + why);
    }
    factorDeformation_ = s.factorDeformation;
  }
  const std::string linearSolver = statistics_.linearSolver;
  statistics_ = s.statistics;  // after factorise(), which counts
  statistics_.linearSolver = linearSolver;
  resumed_ = true;
}

template <int D>
void NewtonSolver<D>::residual(Eigen::VectorXd& r) const {
  const auto& free = dofs_.freeParticles();
  r.resize(D * static_cast<Index>(free.size()));
  for (std::size_t d = 0; d < free.size(); ++d)
    r.template segment<D>(D * d) = solver_.netForce(free[d]);
}

template <int D>
double NewtonSolver<D>::balanceRatio(Eigen::VectorXd& r) {
  if (rigid_) {
    rigid_->update(dofs_.freeParticles(), scene_.particles.referencePosition,
                   scene_.particles.displacement);
    rigid_->project(r);
  }
  const double ratio = solver_.residualRatio();  // of the projected residual for a free body
  referenceForce_ = ratio > 0.0 ? r.norm() / ratio : r.norm();
  return ratio;
}

template <int D>
double NewtonSolver<D>::displacementNorm() const {
  double s = 0.0;
  for (Index i : dofs_.freeParticles())
    s += scene_.particles.displacement[i].squaredNorm();
  return std::sqrt(s);
}

template <int D>
void NewtonSolver<D>::move(const Eigen::VectorXd& du, double s) {
  auto& u = scene_.particles.displacement;
  const auto& free = dofs_.freeParticles();
  for (std::size_t d = 0; d < free.size(); ++d)
    u[free[d]] += s * du.template segment<D>(D * d);
  solver_.reevaluate();
}

template <int D>
bool NewtonSolver<D>::updateMultigrid(double t, const std::vector<Vec<D>>& u,
                                      std::span<const Mat<D>> F,
                                      const std::vector<typename TaylorQuadrature<D>::SymMatrix>& G,
                                      std::string& why) {
  const auto t0 = Clock::now();
  factorised_ = multigrid_->update(t, u, why);
  statistics_.factorisationSeconds += seconds(t0);
  statistics_.nonZeros = multigrid_->coarsestNonZeros();
  statistics_.factorNonZeros = multigrid_->coarsestFactorNonZeros();
  ++statistics_.factorisations;
  factorDeformation_.assign(F.begin(), F.end());
  factorTime_ = t;
  factorDisplacement_ = u;
  factorSecondGradients_ = G;
  return factorised_;
}

template <int D>
bool NewtonSolver<D>::factorise(std::string& why) {
  if (multigrid_) {
    const TaylorQuadrature<D>* q = solver_.forces().quadrature();
    return updateMultigrid(
        loadTime_, scene_.particles.displacement, solver_.forces().deformationGradient(),
        q ? q->secondGradients() : std::vector<typename TaylorQuadrature<D>::SymMatrix>{}, why);
  }
  auto t0 = Clock::now();
  const auto& K = tangent_.assemble();
  statistics_.nonZeros = K.nonZeros();
  statistics_.assemblySeconds += seconds(t0);
  t0 = Clock::now();
  factorised_ = factor_.factorise(rigid_ ? shiftDiagonal(K) : K);
  const auto& F = solver_.forces().deformationGradient();
  factorDeformation_.assign(F.begin(), F.end());
  statistics_.factorisationSeconds += seconds(t0);
  statistics_.factorNonZeros = factor_.factorNonZeros();
  ++statistics_.factorisations;
  if (!factorised_)
    why =
        "the assembled tangent stiffness is not positive definite (a buckling or material "
        "instability, or a body not held against rigid motion)";
  return factorised_;
}

template <int D>
void NewtonSolver<D>::applyTangent(const Eigen::VectorXd& v, Eigen::VectorXd& Kv) {
  tangent_.apply(v, Kv);
  if (!following_) return;
  // The pressures act on every particle of their facets: the variation of all of them (T v),
  // and the product back onto the unknowns (T^T), as for the forces.
  dofs_.expand(v, variation_);
  std::fill(loadProduct_.begin(), loadProduct_.end(), Vec<D>::Zero());
  const auto& p = scene_.particles;
  for (const auto& load : scene_.loads)
    if (load.following)
      load.following->addStiffnessProduct(p.referencePosition, p.displacement,
                                          load.ramp.factor(loadTime_), variation_, loadProduct_);
  dofs_.gather(loadProduct_, loadStiffness_);
  Kv += loadStiffness_;
}

// Preconditioned conjugate gradients on the exact K (BiCGSTAB with a following pressure); false
// on negative curvature, a breakdown or a stall.
template <int D>
bool NewtonSolver<D>::solveLinear(const Eigen::VectorXd& r, Eigen::VectorXd& du, std::string& why) {
  const auto t0 = Clock::now();
  // Relative to r, but no tighter than the Newton tolerance needs (r may be at round-off).
  const double forceScale = referenceForce_;
  const double target =
      std::max(settings_.linearTolerance * r.norm(), 0.1 * settings_.tolerance * forceScale);
  du = precondition(r);
  ConjugateGradientResult cg;
  if (following_) {
    const BiCgStabResult b = biCgStab(
        [&](const Eigen::VectorXd& v, Eigen::VectorXd& Kv) {
          applyTangent(v, Kv);
          if (rigid_) rigid_->project(Kv);
        },
        [&](const Eigen::VectorXd& v) { return precondition(v); }, r, du, target, kMaxKrylov,
        kStall);
    cg.iterations = b.iterations;
    cg.residual = b.residual;
  } else {
    cg = conjugateGradients(
        [&](const Eigen::VectorXd& v, Eigen::VectorXd& Kv) {
          tangent_.apply(v, Kv);
          // A free body: the conjugate gradients run on (1 - Q Q^T) K. K is only nearly
          // singular along Q (rotations about the present positions), and the rigid part of
          // K v would sit in the residual out of the projected corrections' reach.
          if (rigid_) rigid_->project(Kv);
        },
        [&](const Eigen::VectorXd& v) { return precondition(v); }, r, du, target, kMaxKrylov,
        kStall);
  }
  const int iterations = cg.iterations;
  statistics_.krylovIterations += iterations;
  statistics_.solveSeconds += seconds(t0);
  lastKrylov_ = iterations;
  if (cg.negativeCurvature) {
    why =
        "the tangent stiffness is not positive definite along a search direction "
        "(buckling or a material instability)";
    return false;
  }
  // Round-off can stall the iteration short of a tight target; a direction that has halved
  // the residual still serves Newton.
  if (cg.residual > target && cg.residual > 0.5 * r.norm()) {
    std::ostringstream msg;
    msg << "the linear solve stalled after " << iterations << " "
        << (following_ ? "BiCGSTAB" : "conjugate-gradient")
        << " iterations at an out-of-balance force of " << cg.residual << " (the Newton target is "
        << settings_.tolerance * forceScale
        << "): below the round-off of this discretisation, or the preconditioner is poor";
    why = msg.str();
    return false;
  }
  return true;
}

template <int D>
bool NewtonSolver<D>::solveAt(double t, std::string& why) {
  solver_.beginStaticStep(t);
  loadTime_ = t;
  Eigen::VectorXd r, du, rTrial;
  history_.clear();
  for (int it = 0; it < settings_.maxIterations; ++it) {
    residual(r);
    const double ratio = balanceRatio(r);
    history_.push_back(ratio);
    if (!std::isfinite(ratio)) {
      why = "the residual is not finite (an inverted particle?)";
      return false;
    }
    if (it > 0 && ratio <= settings_.tolerance &&
        lastStep_ <= settings_.displacementTolerance * std::max(displacementNorm(), 1e-300))
      return true;
    // The exact tangent at the present state for the product; the factorised matrix, only a
    // preconditioner, is renewed when it has gone stale (too many conjugate-gradient iterations).
    tangent_.update(solver_.forces().deformationGradient());
    tangent_.updateQuadrature(solver_.forces().quadrature(),
                              solver_.forces().deformationGradient());
    if (!factorised_ || lastKrylov_ > kRefactorAfter)
      if (!factorise(why)) return false;
    if (!solveLinear(r, du, why)) {
      // A stale preconditioner may be the reason: once more with a fresh one; a multigrid the
      // solver chose itself gives way to the direct factor.
      if (multigrid_ && settings_.preconditioner == NewtonPreconditioner::Auto)
        useCholesky("the multigrid conjugate gradients stalled at load time t = " +
                    std::to_string(t) + " s");
      if (!factorise(why) || !solveLinear(r, du, why)) return false;
    }
    ++statistics_.iterations;
    // Backtracking on |r|: the full step unless it makes the residual grow.
    const double r0 = r.norm();
    double s = 1.0;
    for (int halvings = 0;; ++halvings) {
      move(du, s);
      residual(rTrial);
      if (rigid_) rigid_->project(rTrial);
      const double r1 = rTrial.norm();
      if ((std::isfinite(r1) && r1 < (1.0 - 1e-4 * s) * r0) || halvings == 8) break;
      move(du, -0.5 * s);
      s *= 0.5;
    }
    lastStep_ = s * du.norm();
  }
  std::ostringstream msg;
  residual(r);
  msg << "not converged in " << settings_.maxIterations << " iterations (out-of-balance ratio "
      << balanceRatio(r) << ", target " << settings_.tolerance << ")";
  why = msg.str();
  return false;
}

template class NewtonSolver<2>;
template class NewtonSolver<3>;

}  // namespace tlsph
