// Moving-least-squares interpolation from a set of source particles to target points:
// u(X_t) ~ sum_c w_tc u_c with a linear basis weighted by the kernel, so exact for every linear
// field (rigid motions and uniform strains included). It carries fields between the particle
// lattices of the multigrid preconditioner, which are not nested.
#pragma once

#include <Eigen/SparseCore>
#include <vector>

#include "method/Kernel.hpp"
#include "model/PeriodicBox.hpp"
#include "model/Types.hpp"

namespace tlsph {

using InterpolationMatrix = Eigen::SparseMatrix<double, Eigen::RowMajor, Index>;

// Rows: targets, columns: sources. A target with fewer than D + 1 sources in general position
// inside the kernel's support gets the kernel-weighted mean (Shepard) instead; one with none
// gets an empty row.
template <int D>
InterpolationMatrix mlsInterpolation(const std::vector<Vec<D>>& targets,
                                     const std::vector<Vec<D>>& sources, const Kernel<D>& kernel,
                                     const PeriodicBox<D>& box = {});

extern template InterpolationMatrix mlsInterpolation<2>(const std::vector<Vec<2>>&,
                                                        const std::vector<Vec<2>>&,
                                                        const Kernel<2>&, const PeriodicBox<2>&);
extern template InterpolationMatrix mlsInterpolation<3>(const std::vector<Vec<3>>&,
                                                        const std::vector<Vec<3>>&,
                                                        const Kernel<3>&, const PeriodicBox<3>&);

}  // namespace tlsph
