// Static equilibrium by Newton-Raphson on the unknowns of the DofMap, with load stepping along
// the scene's ramps ([static] solver = newton; DESIGN.md section 3):
//   K(u) du = r(u),  r = f_int + f_ext on the free particles (ghost forces chained), u += s du,
// with K the exact tangent (TangentStiffness::apply) and the linear system solved by conjugate
// gradients preconditioned with the factorised assembled matrix (exact when the hourglass
// penalty is off, so one iteration; with the penalty it bounds the penalty's part from above).
// The step length s comes from a backtracking line search on |r|. A load step that does not
// converge is halved; the scene is left at the last converged state when the solve fails.
#pragma once

#include <Eigen/Sparse>
#include <chrono>
#include <cmath>
#include <functional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "tlsph/DofMap.hpp"
#include "tlsph/Errors.hpp"
#include "tlsph/Solver.hpp"
#include "tlsph/SparseCholesky.hpp"
#include "tlsph/TangentStiffness.hpp"

namespace tlsph {

struct NewtonSettings {
  int loadSteps = 1;                    // equal steps up to the end of the longest ramp
  double tolerance = 1e-5;              // out-of-balance force ratio (Solver::residualRatio)
  double displacementTolerance = 1e-8;  // |du| / |u| of the last Newton correction
  int maxIterations = 30;               // Newton iterations per load step
  int maxCuts = 6;                      // halvings of a load step before the solve gives up
  double linearTolerance = 1e-6;        // relative residual of the inner conjugate gradients
};

// What a Newton solve did, for the run record.
struct NewtonStatistics {
  int loadSteps = 0;          // converged load steps
  int iterations = 0;         // Newton iterations in all
  long krylovIterations = 0;  // conjugate-gradient iterations in all
  int factorisations = 0;
  long nonZeros = 0;        // stored entries of the assembled matrix (lower triangle)
  long factorNonZeros = 0;  // stored entries of its Cholesky factor
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
};

// A Newton solve that could not reach equilibrium; the message says at which load and why.
class NewtonFailure : public std::runtime_error {
  using std::runtime_error::runtime_error;
};

template <int D>
class NewtonSolver {
 public:
  NewtonSolver(Scene<D>& scene, Solver<D>& solver, const NewtonSettings& settings);

  const NewtonStatistics& statistics() const { return statistics_; }
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
  double displacementNorm() const;
  void move(const Eigen::VectorXd& du, double s);
  bool factorise(std::string& why);
  // Preconditioned conjugate gradients on the exact K; false on negative curvature.
  bool solveLinear(const Eigen::VectorXd& r, Eigen::VectorXd& du, std::string& why);
  bool solveAt(double t, std::string& why);

  Scene<D>& scene_;
  Solver<D>& solver_;
  NewtonSettings settings_;
  DofMap<D> dofs_;
  TangentStiffness<D> tangent_;
  SparseCholesky factor_;
  // Conjugate-gradient iterations: the most per solve, and how many make the preconditioner stale.
  static constexpr int kMaxKrylov = 500;
  static constexpr int kRefactorAfter = 25;
  static constexpr int kStall = 20;  // iterations over which the residual must halve
  bool factorised_ = false;
  double lastStep_ = 0.0;
  int lastKrylov_ = 0;
  NewtonStatistics statistics_;
  // Load stepping (run()): the load time reached, the step length, its halvings so far.
  double done_ = 0.0, increment_ = 0.0;
  int cuts_ = 0;
  bool started_ = false, resumed_ = false;
  std::vector<Mat<D>> factorDeformation_;
};

extern template class NewtonSolver<2>;
extern template class NewtonSolver<3>;

}  // namespace tlsph
