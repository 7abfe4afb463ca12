// The number of eigenvalues of K phi = lambda M phi below a shift sigma, from the inertia of
// K - sigma M (Sylvester's law of inertia: the congruent factorisation L D L^T has as many
// negative entries in D as K - sigma M has negative eigenvalues, and with M positive definite
// those are the eigenvalues of (K, M) below sigma). The Sturm-sequence check of FEM
// eigensolvers: it counts the modes a Lanczos run must have found, independently of that run.
// With CHOLMOD: its fill-reducing ordering and supernodal symbolic factor, and the Schur
// complements of the supernodes' dense blocks (Inertia.cpp says why that counts); without it
// Eigen's SimplicialLDLT (AMD ordering, no pivoting). The symbolic analysis is done once for
// every shift; a shift on an eigenvalue (an exactly zero pivot) is reported, and the callers
// keep a relative gap from the eigenvalues.
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

  // Entries of the factor's blocks (its memory), known before any factorisation.
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
