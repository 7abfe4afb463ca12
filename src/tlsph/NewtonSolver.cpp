// NewtonSolver (see the header), compiled once for 2D and 3D.
#include "tlsph/NewtonSolver.hpp"

#include "tlsph/ConjugateGradients.hpp"

namespace tlsph {

template <int D>
NewtonSolver<D>::NewtonSolver(Scene<D>& scene, Solver<D>& solver, const NewtonSettings& settings)
    : scene_(scene),
      solver_(solver),
      settings_(settings),
      dofs_(scene.particles, scene.mirrorGhosts),
      tangent_(solver.reference(), scene.materials, scene.particles.material,
               scene.particles.volume, scene.hourglass(), dofs_, scene.quadrature) {
  statistics_.linearSolver = SparseCholesky::name();
  if (!tangent_.assemblyExact())
    statistics_.linearSolver = "conjugate gradients preconditioned by " + statistics_.linearSolver;
  if (settings.loadSteps < 1) throw SetupError("[static] load_steps must be at least 1");
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
          << " s). Try more load steps ([static] load_steps), or solver = damped.";
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
  if (factorised_) s.factorDeformation = factorDeformation_;
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
  if (s.factorised) {
    // The same matrix as before the stop: the tangent at the saved F, factorised again.
    if (s.factorDeformation.size() != scene_.particles.displacement.size())
      throw SetupError("the saved Newton state does not fit the scene (particle count)");
    tangent_.update(s.factorDeformation);
    std::string why;
    if (!factorise(why)) throw NewtonFailure("Newton solver: on restart, " + why);
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
bool NewtonSolver<D>::factorise(std::string& why) {
  auto t0 = Clock::now();
  const auto& K = tangent_.assemble();
  statistics_.nonZeros = K.nonZeros();
  statistics_.assemblySeconds += seconds(t0);
  t0 = Clock::now();
  factorised_ = factor_.factorise(K);
  factorDeformation_ = solver_.forces().deformationGradient();
  statistics_.factorisationSeconds += seconds(t0);
  statistics_.factorNonZeros = factor_.factorNonZeros();
  ++statistics_.factorisations;
  if (!factorised_)
    why =
        "the assembled tangent stiffness is not positive definite (a buckling or material "
        "instability, or a body not held against rigid motion)";
  return factorised_;
}

// Preconditioned conjugate gradients on the exact K; false on negative curvature.
template <int D>
bool NewtonSolver<D>::solveLinear(const Eigen::VectorXd& r, Eigen::VectorXd& du, std::string& why) {
  const auto t0 = Clock::now();
  // Relative to r, but no tighter than the Newton tolerance needs (r may be at round-off).
  const double ratio = solver_.residualRatio();
  const double forceScale = ratio > 0.0 ? r.norm() / ratio : r.norm();
  const double target =
      std::max(settings_.linearTolerance * r.norm(), 0.1 * settings_.tolerance * forceScale);
  du = factor_.solve(r);
  const ConjugateGradientResult cg = conjugateGradients(
      [&](const Eigen::VectorXd& v, Eigen::VectorXd& Kv) { tangent_.apply(v, Kv); },
      [&](const Eigen::VectorXd& v) { return factor_.solve(v); }, r, du, target, kMaxKrylov,
      kStall);
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
    msg << "the linear solve stalled after " << iterations
        << " conjugate-gradient iterations at an out-of-balance force of " << cg.residual
        << " (the Newton target is " << settings_.tolerance * forceScale
        << "): below the round-off of this discretisation, or the preconditioner is poor";
    why = msg.str();
    return false;
  }
  return true;
}

template <int D>
bool NewtonSolver<D>::solveAt(double t, std::string& why) {
  solver_.beginStaticStep(t);
  Eigen::VectorXd r, du, rTrial;
  for (int it = 0; it < settings_.maxIterations; ++it) {
    const double ratio = solver_.residualRatio();
    if (!std::isfinite(ratio)) {
      why = "the residual is not finite (an inverted particle?)";
      return false;
    }
    if (it > 0 && ratio <= settings_.tolerance &&
        lastStep_ <= settings_.displacementTolerance * std::max(displacementNorm(), 1e-300))
      return true;
    residual(r);
    // The exact tangent at the present state for the product; the factorised matrix, only a
    // preconditioner, is renewed when it has gone stale (too many conjugate-gradient iterations).
    tangent_.update(solver_.forces().deformationGradient());
    tangent_.updateQuadrature(solver_.forces().quadrature(),
                              solver_.forces().deformationGradient());
    if (!factorised_ || lastKrylov_ > kRefactorAfter)
      if (!factorise(why)) return false;
    if (!solveLinear(r, du, why)) {
      // A stale preconditioner may be the reason: once more with a fresh one.
      if (!factorise(why) || !solveLinear(r, du, why)) return false;
    }
    ++statistics_.iterations;
    // Backtracking on |r|: the full step unless it makes the residual grow.
    const double r0 = r.norm();
    double s = 1.0;
    for (int halvings = 0;; ++halvings) {
      move(du, s);
      residual(rTrial);
      const double r1 = rTrial.norm();
      if ((std::isfinite(r1) && r1 < (1.0 - 1e-4 * s) * r0) || halvings == 8) break;
      move(du, -0.5 * s);
      s *= 0.5;
    }
    lastStep_ = s * du.norm();
  }
  std::ostringstream msg;
  msg << "not converged in " << settings_.maxIterations << " iterations (out-of-balance ratio "
      << solver_.residualRatio() << ", target " << settings_.tolerance << ")";
  why = msg.str();
  return false;
}

template class NewtonSolver<2>;
template class NewtonSolver<3>;

}  // namespace tlsph
