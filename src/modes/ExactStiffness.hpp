// The exact tangent stiffness K (TangentStiffness::apply()) as a sparse matrix, for what needs K
// itself and not a preconditioner of it: the inertia count of K - sigma M (Inertia.hpp).
//
// TangentStiffness::assemble() is K only without the hourglass penalty and with the nodal
// quadrature (assemblyExact()); with the penalty it is an upper bound of the penalty's part and
// with the Taylor quadrature it leaves that term out. Otherwise K is probed: its columns are
// recovered from products K e_G with e_G the sum of the unit vectors of one component on a group
// G of unknowns whose rows of K do not overlap (a distance colouring of the unknowns). Which
// unknowns a column reaches follows from the neighbour graph: the strain energy and the Taylor
// term of particle I couple the particles of I's stencil (two neighbour hops apart), the
// penalty's pair (I, J) the stencils of I and J (three hops); a mirrored ghost counts as the
// unknowns it follows (no hop). The colouring keeps a group's members more than twice that many
// hops apart, so each row of K e_G comes from one member. The matrix is kept only if a product
// with random vectors matches apply() to 1e-10 (relative), so a stencil wider than assumed is
// found, not silently wrong.
#pragma once

#include <Eigen/SparseCore>
#include <string>

#include "implicit/DofMap.hpp"
#include "implicit/TangentStiffness.hpp"
#include "method/ReferenceConfiguration.hpp"

namespace tlsph {

struct ExactStiffness {
  using Matrix = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;
  Matrix lower;  // lower triangle of K (empty when not made)
  bool made = false;
  std::string method;            // "assembled" or "probed"
  std::string reason;            // why not made
  long products = 0;             // K v products the probing took
  int groups = 0;                // groups of unknowns (colours)
  long nonZeros = 0;             // stored entries of `lower`
  double productMismatch = 0.0;  // |K_sparse v - K v| / |K v| for a random v
  double seconds = 0.0;
};

// The exact K of `K` (whose update() and updateQuadrature() are done), on the unknowns of
// `dofs`. Not made (made = false, reason says why) when the lower triangle would hold more than
// maxNonZeros entries or the probed matrix does not reproduce apply().
template <int D>
ExactStiffness exactStiffness(TangentStiffness<D>& K, const ReferenceConfiguration<D>& ref,
                              const DofMap<D>& dofs, bool penalty, long maxNonZeros);

// max over v of |K_sparse v - K v| / |K v| for `samples` random v (seeded): the test of a
// sparse K against the operator.
template <int D>
double productMismatch(TangentStiffness<D>& K, const ExactStiffness::Matrix& lower, int samples);

extern template ExactStiffness exactStiffness<2>(TangentStiffness<2>&,
                                                 const ReferenceConfiguration<2>&, const DofMap<2>&,
                                                 bool, long);
extern template ExactStiffness exactStiffness<3>(TangentStiffness<3>&,
                                                 const ReferenceConfiguration<3>&, const DofMap<3>&,
                                                 bool, long);
extern template double productMismatch<2>(TangentStiffness<2>&, const ExactStiffness::Matrix&, int);
extern template double productMismatch<3>(TangentStiffness<3>&, const ExactStiffness::Matrix&, int);

}  // namespace tlsph
