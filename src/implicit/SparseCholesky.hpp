// Sparse Cholesky factorisation of a symmetric positive definite matrix given by its lower
// triangle (the assembled tangent stiffness): CHOLMOD's supernodal factorisation through Eigen's
// CholmodSupport when the build has SuiteSparse (TLSPH_CHOLMOD), Eigen's SimplicialLDLT otherwise.
// Compiled once, so that the solver headers do not pull in CHOLMOD.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <memory>
#include <string>

namespace tlsph {

class SparseCholesky {
 public:
  using Matrix = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

  SparseCholesky();
  ~SparseCholesky();
  SparseCholesky(const SparseCholesky&) = delete;
  SparseCholesky& operator=(const SparseCholesky&) = delete;

  // Factorises `lower` (lower triangle referenced); the symbolic analysis is kept for later
  // matrices of the same pattern. False when the matrix is not positive definite.
  bool factorise(const Matrix& lower);
  Eigen::VectorXd solve(const Eigen::VectorXd& b) const;
  // Stored entries of the factor (a measure of its memory), 0 when unknown.
  long factorNonZeros() const;
  static std::string name();

 private:
  struct Implementation;
  std::unique_ptr<Implementation> impl_;
  bool analysed_ = false;
};

}  // namespace tlsph
