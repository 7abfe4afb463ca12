// The number of eigenvalues of K phi = lambda M phi below a shift sigma, from the inertia of
// K - sigma M (Sylvester's law of inertia: the congruent factorisation L D L^T has as many
// negative entries in D as K - sigma M has negative eigenvalues, and with M positive definite
// those are the eigenvalues of (K, M) below sigma). The Sturm-sequence check of FEM
// eigensolvers: it counts the modes a Lanczos run must have found, independently of that run.
// Eigen's SimplicialLDLT (fill-reducing AMD ordering, no pivoting: fine for a shift not too
// close to an eigenvalue, which the callers keep a relative gap from); the symbolic analysis is
// done once for every shift.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <memory>

namespace tlsph {

class Inertia {
 public:
  using Matrix = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

  // K by its lower triangle (every diagonal entry stored), M diagonal (the masses).
  Inertia(const Matrix& lowerK, const Eigen::VectorXd& mass);
  ~Inertia();
  Inertia(const Inertia&) = delete;
  Inertia& operator=(const Inertia&) = delete;

  // Entries of the factor L D L^T (its memory), known before any factorisation.
  long factorNonZeros() const;
  // Eigenvalues of (K, M) below sigma; -1 when the factorisation breaks down (an exactly zero
  // pivot: sigma on an eigenvalue).
  long countBelow(double sigma);
  long factorisations() const { return factorisations_; }
  double seconds() const { return seconds_; }

 private:
  struct Implementation;
  std::unique_ptr<Implementation> impl_;
  long factorisations_ = 0;
  double seconds_ = 0.0;
};

}  // namespace tlsph
