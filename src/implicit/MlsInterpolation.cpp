// mlsInterpolation (see the header), compiled once for 2D and 3D.
#include "implicit/MlsInterpolation.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>

#include "method/NeighbourList.hpp"

namespace tlsph {

template <int D>
InterpolationMatrix mlsInterpolation(const std::vector<Vec<D>>& targets,
                                     const std::vector<Vec<D>>& sources, const Kernel<D>& kernel,
                                     const PeriodicBox<D>& box) {
  const NeighbourList nb = buildNeighbourList<D>(targets, sources, kernel.supportRadius(), box);
  const Index nt = static_cast<Index>(targets.size());
  const double H = kernel.supportRadius();
  using Basis = Eigen::Matrix<double, D + 1, 1>;
  using Moment = Eigen::Matrix<double, D + 1, D + 1>;
  // The weights take the search's pattern (rows sorted by source): a row-major matrix.
  std::vector<double> value(nb.pairCount(), 0.0);
#pragma omp parallel for schedule(dynamic, 256)
  for (Index t = 0; t < nt; ++t) {
    auto basis = [&](Index c) {
      Basis q;
      q[0] = 1.0;
      q.template tail<D>() = box.separation(sources[c], targets[t]) / H;
      return q;
    };
    Moment M = Moment::Zero();
    double total = 0.0;
    for (Index k = nb.offset[t]; k < nb.offset[t + 1]; ++k) {
      const Index c = nb.neighbour[k];
      const double w = kernel.value(box.separation(sources[c], targets[t]).norm());
      value[k] = w;
      M.noalias() += w * basis(c) * basis(c).transpose();
      total += w;
    }
    if (!(total > 0.0)) continue;
    const Eigen::SelfAdjointEigenSolver<Moment> eigen(M);
    const bool linear = eigen.eigenvalues().minCoeff() > 1e-8 * eigen.eigenvalues().maxCoeff();
    Basis row = Basis::Zero();  // e_0^T M^{-1}
    if (linear)
      row = eigen.eigenvectors() * (eigen.eigenvalues().cwiseInverse().asDiagonal() *
                                    eigen.eigenvectors().row(0).transpose());
    for (Index k = nb.offset[t]; k < nb.offset[t + 1]; ++k)
      value[k] = linear ? value[k] * row.dot(basis(nb.neighbour[k])) : value[k] / total;
  }
  InterpolationMatrix W(nt, static_cast<Index>(sources.size()));
  W.resizeNonZeros(nb.pairCount());
  std::copy(nb.offset.begin(), nb.offset.end(), W.outerIndexPtr());
  std::copy(nb.neighbour.begin(), nb.neighbour.end(), W.innerIndexPtr());
  std::copy(value.begin(), value.end(), W.valuePtr());
  return W;
}

template InterpolationMatrix mlsInterpolation<2>(const std::vector<Vec<2>>&,
                                                 const std::vector<Vec<2>>&, const Kernel<2>&,
                                                 const PeriodicBox<2>&);
template InterpolationMatrix mlsInterpolation<3>(const std::vector<Vec<3>>&,
                                                 const std::vector<Vec<3>>&, const Kernel<3>&,
                                                 const PeriodicBox<3>&);

}  // namespace tlsph
