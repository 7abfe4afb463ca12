#include "modes/ExactStiffness.hpp"

#include <algorithm>
#include <chrono>
#include <deque>
#include <random>
#include <sstream>
#include <utility>
#include <vector>

namespace tlsph {

namespace {

// The particle graph the stencils live on: neighbour pairs one hop apart, a mirrored ghost and
// the particles it follows no hop apart (its displacement is theirs).
template <int D>
struct StencilGraph {
  const NeighbourList& nb;
  std::vector<std::vector<Index>> same;  // no-hop links (ghost <-> followed particles)

  StencilGraph(const ReferenceConfiguration<D>& ref, const DofMap<D>& dofs)
      : nb(ref.neighbours), same(ref.particleCount()) {
    for (Index i = 0; i < ref.particleCount(); ++i) {
      const auto [first, last] = dofs.terms(i);
      for (auto t = first; t != last; ++t) {
        const Index j = dofs.freeParticles()[t->dof];
        if (j == i) continue;
        same[i].push_back(j);
        same[j].push_back(i);
      }
    }
  }
};

// Breadth-first search from particle `source` to `depth` hops (0-1 weights), calling
// visit(particle, hops) once per particle reached. `hops` is scratch (-1 = not reached),
// returned to -1 for the particles reached.
template <int D, class Visit>
void search(const StencilGraph<D>& g, Index source, int depth, std::vector<int>& hops,
            std::vector<Index>& reached, Visit&& visit) {
  std::deque<Index> queue;
  reached.clear();
  hops[source] = 0;
  reached.push_back(source);
  queue.push_back(source);
  while (!queue.empty()) {
    const Index i = queue.front();
    queue.pop_front();
    const int h = hops[i];
    for (Index j : g.same[i])
      if (hops[j] < 0 || hops[j] > h) {
        if (hops[j] < 0) reached.push_back(j);
        hops[j] = h;
        queue.push_front(j);
      }
    if (h == depth) continue;
    for (Index k = g.nb.offset[i]; k < g.nb.offset[i + 1]; ++k) {
      const Index j = g.nb.neighbour[k];
      if (hops[j] < 0) {
        reached.push_back(j);
        hops[j] = h + 1;
        queue.push_back(j);
      }
    }
  }
  for (Index i : reached) {
    visit(i, hops[i]);
    hops[i] = -1;
  }
}

}  // namespace

template <int D>
double productMismatch(TangentStiffness<D>& K, const ExactStiffness::Matrix& lower, int samples) {
  std::mt19937_64 random(20261204);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  double worst = 0.0;
  for (int s = 0; s < samples; ++s) {
    Eigen::VectorXd v(K.size()), Kv;
    for (Eigen::Index i = 0; i < v.size(); ++i)
      v[i] = uniform(random);
    K.apply(v, Kv);
    const Eigen::VectorXd sparse = lower.template selfadjointView<Eigen::Lower>() * v;
    worst = std::max(worst, (sparse - Kv).norm() / Kv.norm());
  }
  return worst;
}

template <int D>
ExactStiffness exactStiffness(TangentStiffness<D>& K, const ReferenceConfiguration<D>& ref,
                              const DofMap<D>& dofs, bool penalty, long maxNonZeros) {
  const auto start = std::chrono::steady_clock::now();
  ExactStiffness out;
  auto finish = [&](ExactStiffness& r) -> ExactStiffness& {
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return r;
  };
  if (K.assemblyExact()) {
    out.lower = K.assemble();
    out.method = "assembled";
  } else {
    const Index unknowns = dofs.size();
    const StencilGraph<D> graph(ref, dofs);
    const int reachHops = penalty ? 3 : 2;
    // Per unknown: the unknowns its column of K reaches (sorted), and its group.
    std::vector<std::vector<Index>> reach(unknowns);
    std::vector<int> group(unknowns, -1), hops(ref.particleCount(), -1), seen;
    std::vector<Index> reached;
    long estimate = 0;
    for (Index d = 0; d < unknowns; ++d) {
      std::vector<Index>& r = reach[d];
      search(graph, dofs.freeParticles()[d], 2 * reachHops, hops, reached, [&](Index i, int h) {
        const Index q = dofs.dofOf(i);
        if (q < 0) return;
        if (h <= reachHops) r.push_back(q);
        // members of one group more than 2 reachHops apart: no row of K is shared
        if (group[q] >= 0) {
          if (group[q] >= static_cast<int>(seen.size())) seen.resize(group[q] + 1, -1);
          seen[group[q]] = static_cast<int>(d);
        }
      });
      std::sort(r.begin(), r.end());
      int c = 0;
      while (c < static_cast<int>(seen.size()) && seen[c] == static_cast<int>(d))
        ++c;
      group[d] = c;
      out.groups = std::max(out.groups, c + 1);
      estimate += static_cast<long>(r.size()) * D * D;
    }
    estimate = (estimate + D * unknowns) / 2;
    if (estimate > maxNonZeros) {
      std::ostringstream why;
      why << "the exact K would hold about " << estimate << " entries (lower triangle), above "
          << "the limit of " << maxNonZeros;
      out.reason = why.str();
      return finish(out);
    }
    std::vector<std::vector<Index>> members(out.groups);
    for (Index d = 0; d < unknowns; ++d)
      members[group[d]].push_back(d);
    const Index n = D * unknowns;
    std::vector<std::vector<std::pair<int, double>>> columns(n);
    Eigen::VectorXd v = Eigen::VectorXd::Zero(n), Kv;
    for (const auto& m : members)
      for (int k = 0; k < D; ++k) {
        for (Index d : m)
          v[D * d + k] = 1.0;
        K.apply(v, Kv);
        ++out.products;
        for (Index d : m) {
          v[D * d + k] = 0.0;
          const Index j = D * d + k;
          auto& column = columns[j];
          for (Index q : reach[d])
            for (int i = 0; i < D; ++i) {
              const Index row = D * q + i;
              // the diagonal always (the factorisations shift it), other entries when not 0
              if (row > j ? Kv[row] != 0.0 : row == j)
                column.emplace_back(static_cast<int>(row), Kv[row]);
            }
        }
      }
    long entries = 0;
    for (const auto& c : columns)
      entries += static_cast<long>(c.size());
    ExactStiffness::Matrix& A = out.lower;
    A.resize(n, n);
    A.resizeNonZeros(entries);
    long at = 0;
    for (Index j = 0; j < n; ++j) {
      A.outerIndexPtr()[j] = static_cast<int>(at);
      for (const auto& [row, value] : columns[j]) {
        A.innerIndexPtr()[at] = row;
        A.valuePtr()[at] = value;
        ++at;
      }
      columns[j] = {};
    }
    A.outerIndexPtr()[n] = static_cast<int>(at);
    out.method = "probed";
  }
  out.nonZeros = out.lower.nonZeros();
  out.productMismatch = productMismatch(K, out.lower, 2);
  if (!(out.productMismatch <= 1e-10)) {
    std::ostringstream why;
    why << "the " << out.method << " sparse K does not reproduce K v (relative mismatch "
        << out.productMismatch << ")";
    out.reason = why.str();
    out.lower = ExactStiffness::Matrix();
    return finish(out);
  }
  out.made = true;
  return finish(out);
}

template ExactStiffness exactStiffness<2>(TangentStiffness<2>&, const ReferenceConfiguration<2>&,
                                          const DofMap<2>&, bool, long);
template ExactStiffness exactStiffness<3>(TangentStiffness<3>&, const ReferenceConfiguration<3>&,
                                          const DofMap<3>&, bool, long);
template double productMismatch<2>(TangentStiffness<2>&, const ExactStiffness::Matrix&, int);
template double productMismatch<3>(TangentStiffness<3>&, const ExactStiffness::Matrix&, int);

}  // namespace tlsph
