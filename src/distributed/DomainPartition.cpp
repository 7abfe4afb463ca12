// DomainPartition (see the header), compiled once for 2D and 3D.
#include "distributed/DomainPartition.hpp"

#include <algorithm>
#include <numeric>

#include "model/Errors.hpp"

#ifdef TLSPH_HAVE_METIS
#include <metis.h>
#endif

namespace tlsph {

namespace {

// A particle's share of the work: its pairs (the passes are pair loops) and itself.
double weightOf(const NeighbourList& nb, Index i) {
  return nb.count(i) + 1.0;
}

}  // namespace

Index DomainPartition::haloTotal() const {
  Index total = 0;
  for (const auto& h : halo)
    total += static_cast<Index>(h.size());
  return total;
}

double DomainPartition::imbalance(const NeighbourList& nb) const {
  std::vector<double> load(parts, 0.0);
  double total = 0.0;
  for (Index i = 0; i < static_cast<Index>(part.size()); ++i) {
    load[part[i]] += weightOf(nb, i);
    total += weightOf(nb, i);
  }
  return *std::max_element(load.begin(), load.end()) / (total / parts);
}

void completePartition(DomainPartition& p, const NeighbourList& nb) {
  const Index n = static_cast<Index>(p.part.size());
  p.owned.assign(p.parts, {});
  p.halo.assign(p.parts, {});
  for (Index i = 0; i < n; ++i)
    p.owned[p.part[i]].push_back(i);
  for (Index i = 0; i < n; ++i)
    for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k) {
      const Index j = nb.neighbour[k];
      if (p.part[j] != p.part[i]) p.halo[p.part[i]].push_back(j);
    }
  for (auto& h : p.halo) {
    std::sort(h.begin(), h.end());
    h.erase(std::unique(h.begin(), h.end()), h.end());
  }
}

void keepTogether(DomainPartition& p, const std::vector<std::pair<Index, Index>>& links,
                  const NeighbourList& nb) {
  if (links.empty()) return;
  std::vector<Index> root(p.part.size());
  std::iota(root.begin(), root.end(), 0);
  auto find = [&](Index i) {
    while (root[i] != i)
      i = root[i] = root[root[i]];
    return i;
  };
  for (const auto& [a, b] : links) {
    const Index ra = find(a), rb = find(b);
    if (ra != rb) root[std::max(ra, rb)] = std::min(ra, rb);  // the root is the lowest index
  }
  for (Index i = 0; i < static_cast<Index>(p.part.size()); ++i)
    p.part[i] = p.part[find(i)];
  completePartition(p, nb);
}

template <int D>
DomainPartition partitionByBisection(const std::vector<Vec<D>>& X, const NeighbourList& nb,
                                     int parts) {
  DomainPartition p;
  p.parts = parts;
  p.method = "bisection";
  p.part.assign(X.size(), 0);
  std::vector<Index> all(X.size());
  std::iota(all.begin(), all.end(), 0);
  // Split `ids` into `count` parts numbered from `first`.
  auto split = [&](auto&& self, std::vector<Index>& ids, int first, int count) -> void {
    if (count == 1 || ids.empty()) {
      for (Index i : ids)
        p.part[i] = first;
      return;
    }
    Vec<D> lo = X[ids.front()], hi = lo;
    for (Index i : ids) {
      lo = lo.cwiseMin(X[i]);
      hi = hi.cwiseMax(X[i]);
    }
    int axis = 0;
    (hi - lo).maxCoeff(&axis);
    // Ties in the coordinate broken by index: the same cut on every run.
    std::sort(ids.begin(), ids.end(), [&](Index a, Index b) {
      return X[a][axis] < X[b][axis] || (X[a][axis] == X[b][axis] && a < b);
    });
    const int left = count / 2;
    double total = 0.0;
    for (Index i : ids)
      total += weightOf(nb, i);
    const double target = total * left / count;
    double sum = 0.0;
    std::size_t cut = 0;
    while (cut < ids.size() && sum + 0.5 * weightOf(nb, ids[cut]) < target)
      sum += weightOf(nb, ids[cut++]);
    std::vector<Index> low(ids.begin(), ids.begin() + cut), high(ids.begin() + cut, ids.end());
    self(self, low, first, left);
    self(self, high, first + left, count - left);
  };
  split(split, all, 0, parts);
  completePartition(p, nb);
  return p;
}

bool haveMetis() {
#ifdef TLSPH_HAVE_METIS
  return true;
#else
  return false;
#endif
}

DomainPartition partitionByMetis(const NeighbourList& nb, int parts) {
#ifdef TLSPH_HAVE_METIS
  DomainPartition p;
  p.parts = parts;
  p.method = "metis";
  const Index n = nb.particleCount();
  p.part.assign(n, 0);
  if (parts > 1 && n > 0) {
    idx_t vertices = n, constraints = 1, count = parts, cut = 0;
    std::vector<idx_t> xadj(nb.offset.begin(), nb.offset.end());
    std::vector<idx_t> adjacency(nb.neighbour.begin(), nb.neighbour.end());
    std::vector<idx_t> weight(n), result(n);
    for (Index i = 0; i < n; ++i)
      weight[i] = static_cast<idx_t>(weightOf(nb, i));
    idx_t options[METIS_NOPTIONS];
    METIS_SetDefaultOptions(options);
    options[METIS_OPTION_SEED] = 1;  // the same partition on every run
    const int status = METIS_PartGraphKway(&vertices, &constraints, xadj.data(), adjacency.data(),
                                           weight.data(), nullptr, nullptr, &count, nullptr,
                                           nullptr, options, &cut, result.data());
    if (status != METIS_OK) throw SetupError("METIS could not partition the neighbour graph");
    std::copy(result.begin(), result.end(), p.part.begin());
  }
  completePartition(p, nb);
  return p;
#else
  (void)nb;
  (void)parts;
  throw SetupError("this build has no METIS (install libmetis-dev and rebuild)");
#endif
}

template <int D>
DomainPartition partitionParticles(const std::vector<Vec<D>>& X, const NeighbourList& nb,
                                   int parts) {
  if (parts <= 1) {
    DomainPartition p;
    p.method = "single";
    p.part.assign(X.size(), 0);
    completePartition(p, nb);
    return p;
  }
  DomainPartition best = partitionByBisection<D>(X, nb, parts);
  if (haveMetis()) {
    DomainPartition metis = partitionByMetis(nb, parts);
    if (metis.haloTotal() < best.haloTotal()) best = std::move(metis);
  }
  return best;
}

template DomainPartition partitionByBisection<2>(const std::vector<Vec<2>>&, const NeighbourList&,
                                                 int);
template DomainPartition partitionByBisection<3>(const std::vector<Vec<3>>&, const NeighbourList&,
                                                 int);
template DomainPartition partitionParticles<2>(const std::vector<Vec<2>>&, const NeighbourList&,
                                               int);
template DomainPartition partitionParticles<3>(const std::vector<Vec<3>>&, const NeighbourList&,
                                               int);

}  // namespace tlsph
