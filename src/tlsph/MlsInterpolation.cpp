// mlsInterpolation (see the header), compiled once for 2D and 3D.
#include "tlsph/MlsInterpolation.hpp"

#include <Eigen/Eigenvalues>

#include "tlsph/NeighbourList.hpp"

namespace tlsph {

template <int D>
InterpolationMatrix mlsInterpolation(const std::vector<Vec<D>>& targets,
                                     const std::vector<Vec<D>>& sources, const Kernel<D>& kernel,
                                     const PeriodicBox<D>& box) {
  // One neighbour search over both sets: the pairs (target, source) are what is needed.
  std::vector<Vec<D>> all(targets);
  all.insert(all.end(), sources.begin(), sources.end());
  const NeighbourList nb = buildNeighbourList<D>(all, kernel.supportRadius(), box);
  const Index nt = static_cast<Index>(targets.size());
  const double H = kernel.supportRadius();
  using Basis = Eigen::Matrix<double, D + 1, 1>;
  using Moment = Eigen::Matrix<double, D + 1, D + 1>;
  std::vector<Eigen::Triplet<double, Index>> entries;
  std::vector<std::pair<Index, double>> weights;
  for (Index t = 0; t < nt; ++t) {
    weights.clear();
    Moment M = Moment::Zero();
    double total = 0.0;
    auto basis = [&](Index c) {
      Basis q;
      q[0] = 1.0;
      q.template tail<D>() = box.separation(sources[c], targets[t]) / H;
      return q;
    };
    for (Index k = nb.offset[t]; k < nb.offset[t + 1]; ++k) {
      const Index c = nb.neighbour[k] - nt;
      if (c < 0) continue;
      const double w = kernel.value(box.separation(sources[c], targets[t]).norm());
      if (w <= 0.0) continue;
      weights.emplace_back(c, w);
      M.noalias() += w * basis(c) * basis(c).transpose();
      total += w;
    }
    if (weights.empty()) continue;
    const Eigen::SelfAdjointEigenSolver<Moment> eigen(M);
    const bool linear = eigen.eigenvalues().minCoeff() > 1e-8 * eigen.eigenvalues().maxCoeff();
    Basis row = Basis::Zero();  // e_0^T M^{-1}
    if (linear)
      row = eigen.eigenvectors() * (eigen.eigenvalues().cwiseInverse().asDiagonal() *
                                    eigen.eigenvectors().row(0).transpose());
    for (const auto& [c, w] : weights)
      entries.emplace_back(t, c, linear ? w * row.dot(basis(c)) : w / total);
  }
  InterpolationMatrix W(nt, static_cast<Index>(sources.size()));
  W.setFromTriplets(entries.begin(), entries.end());
  return W;
}

template InterpolationMatrix mlsInterpolation<2>(const std::vector<Vec<2>>&,
                                                 const std::vector<Vec<2>>&, const Kernel<2>&,
                                                 const PeriodicBox<2>&);
template InterpolationMatrix mlsInterpolation<3>(const std::vector<Vec<3>>&,
                                                 const std::vector<Vec<3>>&, const Kernel<3>&,
                                                 const PeriodicBox<3>&);

}  // namespace tlsph
