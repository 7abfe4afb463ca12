// Static equilibrium by Newton-Raphson on the unknowns of the DofMap, with load stepping along
// the scene's ramps ([static] solver = newton; docs/method.md section 3):
//   K(u) du = r(u),  r = f_int + f_ext on the free particles (ghost forces chained), u += s du,
// with K the exact tangent (TangentStiffness::apply) and the linear system solved by conjugate
// gradients preconditioned with the factorised assembled matrix (exact when the hourglass
// penalty is off, so one iteration; with the penalty it bounds the penalty's part from above).
// A following pressure adds its load stiffness (FollowingPressure.hpp), which is not
// symmetric: such a scene's system is solved by BiCGSTAB with the same preconditioner.
// The step length s comes from a backtracking line search on |r|. A load step that does not
// converge is halved; the scene is left at the last converged state when the solve fails.
#pragma once

#include <Eigen/Sparse>
#include <chrono>
#include <cmath>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "explicit/Solver.hpp"
#include "implicit/DofMap.hpp"
#include "implicit/MultigridPreconditioner.hpp"
#include "implicit/SparseCholesky.hpp"
#include "implicit/TangentStiffness.hpp"
#include "model/Errors.hpp"
#include "model/RigidModes.hpp"

namespace tlsph {

// What preconditions the conjugate gradients: the sparse Cholesky factor of the assembled
// tangent, a multigrid V-cycle over the scene rebuilt at coarser spacings, or (auto) the
// multigrid from autoMultigridUnknowns scalar unknowns on when the scene can be coarsened and
// is not nearly incompressible (falling back to the factor if its iteration stalls).
enum class NewtonPreconditioner { Auto, Cholesky, Multigrid };
inline const char* newtonPreconditionerName(NewtonPreconditioner p) {
  return p == NewtonPreconditioner::Cholesky    ? "cholesky"
         : p == NewtonPreconditioner::Multigrid ? "multigrid"
                                                : "auto";
}

struct NewtonSettings {
  NewtonPreconditioner preconditioner = NewtonPreconditioner::Auto;
  // auto: the Cholesky factor below this many scalar unknowns, or for a material with a Poisson
  // ratio from autoPoissonLimit on (measured crossovers, docs/static.md)
  long autoMultigridUnknowns = 15000;
  double autoPoissonLimit = 0.45;
  int loadSteps = 1;                    // equal steps up to the end of the longest ramp
  double tolerance = 1e-5;              // out-of-balance force ratio (Solver::residualRatio)
  double displacementTolerance = 1e-8;  // |du| / |u| of the last Newton correction
  int maxIterations = 30;               // Newton iterations per load step
  int maxCuts = 6;                      // halvings of a load step before the solve gives up
  double linearTolerance = 1e-6;        // relative residual of the inner conjugate gradients
};

// The same scene at `factor` times the particle spacing (2, 4, ...), for the multigrid levels;
// null when it cannot be built that coarse.
template <int D>
using SceneCoarsening = std::function<std::unique_ptr<Scene<D>>(int factor)>;

// What a Newton solve did, for the run record.
struct NewtonStatistics {
  int loadSteps = 0;          // converged load steps
  int iterations = 0;         // Newton iterations in all
  long krylovIterations = 0;  // conjugate-gradient iterations in all
  int factorisations = 0;
  // Stored entries of the assembled matrix (lower triangle) and of its Cholesky factor; with
  // the multigrid, the coarsest level's (the fine K is never assembled).
  long nonZeros = 0;
  long factorNonZeros = 0;
  int levels = 1;  // multigrid levels (1: the Cholesky factor of the whole matrix)
  double assemblySeconds = 0.0, factorisationSeconds = 0.0, solveSeconds = 0.0;
  std::string linearSolver;
};

// Where a Newton solve stands between two load steps, for checkpoint/restart: the load reached,
// the step-size control, and the state the preconditioner was factorised at (the factor is
// rebuilt from it, so a restarted solve takes the same iterations bit for bit).
template <int D>
struct NewtonState {
  double done = 0.0;       // load time reached
  double increment = 0.0;  // present load-step length
  int cuts = 0;
  bool started = false;  // a first load step has converged
  bool factorised = false;
  int lastKrylov = 0;
  double lastStep = 0.0;
  NewtonStatistics statistics;
  std::vector<Mat<D>> factorDeformation;  // F at the last factorisation
  // Multigrid: the load time, every particle's u and the Taylor second gradients at the last
  // preconditioner update (the coarse levels and the smoother are rebuilt from them).
  double factorTime = 0.0;
  std::vector<Vec<D>> factorDisplacement;
  std::vector<typename TaylorQuadrature<D>::SymMatrix> factorSecondGradients;
};

// A Newton solve that could not reach equilibrium; the message says at which load and why.
class NewtonFailure : public std::runtime_error {
  using std::runtime_error::runtime_error;
};

template <int D>
class NewtonSolver {
 public:
  // `coarsen` builds the multigrid levels (preconditioner multigrid or auto); without it the
  // Cholesky factor is used.
  NewtonSolver(Scene<D>& scene, Solver<D>& solver, const NewtonSettings& settings,
               const SceneCoarsening<D>& coarsen = {}, const SolverSettings& solverSettings = {});
  ~NewtonSolver();

  const NewtonStatistics& statistics() const { return statistics_; }
  // The out-of-balance ratios (Solver::residualRatio) of the last load step tried, one per
  // iteration and the last one's result: the convergence rate, for tests and studies.
  const std::vector<double>& residualHistory() const { return history_; }
  const DofMap<D>& dofs() const { return dofs_; }
  TangentStiffness<D>& tangent() { return tangent_; }

  // Solves the load steps up to the end of the ramps; onStep() after each converged one, which
  // returns false to stop there. Throws NewtonFailure with the scene at the last converged state.
  // After resume(), continues from the saved load step.
  void run(const std::function<bool()>& onStep);

  // The state between load steps (call from onStep), and its restoration into a new solver of
  // the same scene whose Solver has been restored to the same step.
  NewtonState<D> state() const;
  void resume(const NewtonState<D>& state);

 private:
  using Clock = std::chrono::steady_clock;
  static double seconds(Clock::time_point since) {
    return std::chrono::duration<double>(Clock::now() - since).count();
  }

  // Residual on the unknowns: the net force on each free particle.
  void residual(Eigen::VectorXd& r) const;
  // Solver::residualRatio; a free body's residual r is first projected off the rigid motions.
  double balanceRatio(Eigen::VectorXd& r);
  double displacementNorm() const;
  void move(const Eigen::VectorXd& du, double s);
  bool factorise(std::string& why);
  // Drops the multigrid for the Cholesky factor (auto mode, after a stall), saying why.
  void useCholesky(const std::string& why);
  // Multigrid: the preconditioner at load time t, displacements u (F, second gradients G).
  bool updateMultigrid(double t, const std::vector<Vec<D>>& u, std::span<const Mat<D>> F,
                       const std::vector<typename TaylorQuadrature<D>::SymMatrix>& G,
                       std::string& why);
  Eigen::VectorXd precondition(const Eigen::VectorXd& r) {
    Eigen::VectorXd z = multigrid_ ? multigrid_->apply(r) : factor_.solve(r);
    if (rigid_) rigid_->project(z);
    return z;
  }
  // Preconditioned conjugate gradients on the exact K (BiCGSTAB with a following pressure);
  // false on negative curvature, a breakdown or a stall.
  bool solveLinear(const Eigen::VectorXd& r, Eigen::VectorXd& du, std::string& why);
  // The exact K on v: the strain and penalty parts, and the following pressures' stiffness.
  void applyTangent(const Eigen::VectorXd& v, Eigen::VectorXd& Kv);
  // The Krylov method's name for the statistics.
  const char* krylovName() const { return following_ ? "BiCGSTAB" : "conjugate gradients"; }
  bool solveAt(double t, std::string& why);

  Scene<D>& scene_;
  Solver<D>& solver_;
  NewtonSettings settings_;
  DofMap<D> dofs_;
  TangentStiffness<D> tangent_;
  SparseCholesky factor_;
  std::unique_ptr<MultigridPreconditioner<D>> multigrid_;  // instead of factor_ when set
  // A body nothing holds (its loads balance): the corrections are kept off its rigid motions.
  std::optional<RigidModes<D>> rigid_;
  double referenceForce_ = 0.0;  // the loads' size in the last balanceRatio (its denominator)
  // Conjugate-gradient iterations: the most per solve, and how many make the preconditioner stale.
  static constexpr int kMaxKrylov = 500;
  static constexpr int kRefactorAfter = 25;
  static constexpr int kStall = 20;  // iterations over which the residual must halve
  // Coarsen until a level has at most this many scalar unknowns (its factor is then cheap).
  static constexpr Index kCoarsestUnknowns = 30000;
  bool factorised_ = false;
  double lastStep_ = 0.0;
  int lastKrylov_ = 0;
  NewtonStatistics statistics_;
  // Load stepping (run()): the load time reached, the step length, its halvings so far.
  double done_ = 0.0, increment_ = 0.0;
  int cuts_ = 0;
  bool started_ = false, resumed_ = false;
  std::vector<Mat<D>> factorDeformation_;
  double factorTime_ = 0.0, loadTime_ = 0.0;
  std::vector<Vec<D>> factorDisplacement_;
  std::vector<typename TaylorQuadrature<D>::SymMatrix> factorSecondGradients_;
  std::vector<double> history_;
  // Some load is a following pressure: the tangent is not symmetric.
  bool following_ = false;
  std::vector<Vec<D>> variation_, loadProduct_;  // per particle, for applyTangent
  Eigen::VectorXd loadStiffness_;
};

extern template class NewtonSolver<2>;
extern template class NewtonSolver<3>;

}  // namespace tlsph
