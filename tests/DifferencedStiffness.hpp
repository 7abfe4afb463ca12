// -d(net force)/du on the free particles by central differences: the reference the tangent
// stiffness tests compare K with.
#pragma once

#include <Eigen/Dense>
#include <vector>

#include "explicit/Solver.hpp"

namespace tlsph::testing {

// Column k is -(f(u + h e_k) - f(u - h e_k)) / 2h over the unknowns D * d + a of the particles
// `free` (in that order); the solver is re-evaluated at u on return.
template <int D>
Eigen::MatrixXd differencedStiffness(Solver<D>& solver, std::vector<Vec<D>>& displacement,
                                     const std::vector<Index>& free, double h) {
  const Index n = D * static_cast<Index>(free.size());
  auto netForce = [&] {
    Eigen::VectorXd f(n);
    for (std::size_t d = 0; d < free.size(); ++d)
      f.template segment<D>(D * d) = solver.netForce(free[d]);
    return f;
  };
  Eigen::MatrixXd K(n, n);
  for (Index k = 0; k < n; ++k) {
    Vec<D>& u = displacement[free[k / D]];
    u[k % D] += h;
    solver.reevaluate();
    const Eigen::VectorXd plus = netForce();
    u[k % D] -= 2.0 * h;
    solver.reevaluate();
    const Eigen::VectorXd minus = netForce();
    u[k % D] += h;
    K.col(k) = -(plus - minus) / (2.0 * h);
  }
  solver.reevaluate();
  return K;
}

}  // namespace tlsph::testing
