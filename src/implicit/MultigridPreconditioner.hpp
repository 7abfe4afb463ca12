// A geometric multigrid V-cycle as the preconditioner of the Newton solver's conjugate
// gradients ([static] preconditioner = multigrid; docs/static.md). The levels are the scene
// itself and the same scene rebuilt at 2, 4, ... times its particle spacing (the caller's
// coarsening); fields move between the lattices by linear moving-least-squares interpolation P
// (coarse to fine) and its transpose. On each level but the coarsest, a Chebyshev polynomial in
// D^-1 K (D: K's diagonal blocks) of degree 2 smooths before and after the coarse correction;
// the coarsest level is solved by a sparse Cholesky factor. With the same symmetric smoother
// before and after, the V-cycle is a symmetric positive definite operator, as conjugate
// gradients need. The finest level's products are the exact matrix-free tangent, the coarser
// levels' their own scenes' tangents at the fine state interpolated onto them.
//
// Why: the direct factor of a plate-like body grows as n^1.7 in entries and faster in time (the
// clamped plate at 8 particles through: 773 M entries, 53 s, 7.8 GB), while a V-cycle costs a
// few force passes and keeps the conjugate-gradient count flat as the resolution grows.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "explicit/Solver.hpp"
#include "implicit/DofMap.hpp"
#include "implicit/SparseCholesky.hpp"
#include "implicit/TangentStiffness.hpp"
#include "model/RigidModes.hpp"
#include "model/Scene.hpp"

namespace tlsph {

template <int D>
class MultigridPreconditioner {
 public:
  static constexpr int kSmootherDegree = 2;
  // The Chebyshev interval [lambda_max / ratio, lambda_max] of D^-1 K: the smoother damps the
  // upper part of the spectrum, the coarse levels the rest.
  static constexpr double kSmoothedRatio = 10.0;

  // `fine` with its unknowns and exact tangent (owned by the Newton solver); `coarse`: the
  // coarser scenes, finest first, the last one solved directly. A coarse scene whose set-up
  // fails ends the hierarchy there; SetupError when the first one does.
  MultigridPreconditioner(const Scene<D>& fine, const DofMap<D>& fineDofs,
                          TangentStiffness<D>& fineTangent,
                          std::vector<std::unique_ptr<Scene<D>>> coarse,
                          const SolverSettings& settings);
  ~MultigridPreconditioner();

  // Renews every level at the fine state u (every particle's displacement) at load time t, the
  // fine tangent being already at that state: coarse tangents at the interpolated displacements,
  // diagonal blocks, spectrum bounds and the coarsest factor. False, with the reason, when a
  // matrix is not positive definite.
  bool update(double t, const std::vector<Vec<D>>& u, std::string& why);

  // z = M^-1 r: one V-cycle from zero.
  Eigen::VectorXd apply(const Eigen::VectorXd& r);

  int levelCount() const { return static_cast<int>(levels_.size()); }
  // Scalar unknowns per level, finest first.
  std::vector<Index> unknowns() const;
  long coarsestNonZeros() const { return coarsestNonZeros_; }
  long coarsestFactorNonZeros() const { return factor_.factorNonZeros(); }
  std::string description() const;

 private:
  struct Level;
  Eigen::VectorXd cycle(std::size_t l, const Eigen::VectorXd& r);
  Eigen::VectorXd smooth(Level& level, const Eigen::VectorXd& r);
  double largestEigenvalue(Level& level);

  std::vector<std::unique_ptr<Level>> levels_;
  SparseCholesky factor_;
  // A free body's coarsest level: its factor is of the shifted matrix, its solution projected
  // off the rigid motions (RigidModes.hpp).
  std::optional<RigidModes<D>> coarsestRigid_;
  long coarsestNonZeros_ = 0;
};

extern template class MultigridPreconditioner<2>;
extern template class MultigridPreconditioner<3>;

}  // namespace tlsph
