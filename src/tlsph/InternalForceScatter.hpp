// The internal force (6.70), with the Taylor quadrature's hyperstress force, summed from its
// sources (issue 12):
//   f_I = V_I (S_I G_I + R_I . Sum_I - sum_J [S_J t_IJ + R_J . T_IJ])
// The gather form (TlsphForces::accumulateForces) loads the neighbour's S_J and R_J at every
// pair: in 3D nine padded columns per pair, which bound that pass out of the first cache
// levels. Here each source J loads its S_J and R_J once and subtracts its two terms from the
// sums of the particles I in its own list. J's row holds, at the position of target I, the
// target's numbers t_IJ and T_IJ, so every term is the same product of the same values; and the
// lists being sorted, a target receives its terms in ascending J, the order of its own list.
// The sums therefore have the same bits as the gather's (test_internal_force_scatter).
//
// Threads: each owns a contiguous range of targets and visits every source with a neighbour in
// that range (a sorted row: one sub-range of it); a source near the edge of two ranges is
// visited by both, each of its pairs by one. The ranges are where the threads met in the pass
// before (MeetInTheMiddle.hpp), any split being as good for the bits. No atomics, and a
// target's terms arrive in the same order whatever the number of threads and the split. A
// distributed rank's sources are the particles with a list (its own and its halo, whose S and R
// the halo exchange brought); targets that are not its own are summed too, and never read.
#pragma once

#include <algorithm>
#include <array>
#include <type_traits>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "tlsph/LargePageAllocator.hpp"
#include "tlsph/MeetInTheMiddle.hpp"
#include "tlsph/NeighbourList.hpp"
#include "tlsph/Padded.hpp"
#include "tlsph/Prefetch.hpp"
#include "tlsph/SharedRows.hpp"
#include "tlsph/TaylorQuadrature.hpp"
#include "tlsph/Types.hpp"

namespace tlsph {

template <int D, bool Taylor>
class InternalForceScatter {
 public:
  static constexpr int P = TaylorQuadrature<D>::P;
  using Sym = typename TaylorQuadrature<D>::Sym;
  using PaddedSymMatrix = typename TaylorQuadrature<D>::PaddedSymMatrix;
  // At source J's m-th pair (target I): t_IJ, and T_IJ with the quadrature.
  using Record = std::conditional_t<Taylor, Eigen::Matrix<double, D + P, 1>, Vec<D>>;

  // t: the gather's rows of t_IJ (each target's own list); T: those of T_IJ (Taylor only).
  // Pairs whose target has no list (a distributed rank's halo edge) get zero: such targets
  // are not the rank's.
  InternalForceScatter(const NeighbourList& nb, const SharedRows<Vec<D>>& t,
                       const SharedRows<Sym>* T)
      : nb_(nb), sums_(static_cast<std::size_t>(nb.particleCount()), PaddedVec<D>::Zero()) {
    PairArray<Record> records(nb.pairCount(), Record::Zero());
    const Index n = nb.particleCount();
    // each source's first and last target (its sorted row's ends; an empty row matches none)
    targetSpan_.assign(static_cast<std::size_t>(n), {n, -1});
    for (Index j = 0; j < n; ++j)
      if (nb.count(j) > 0) {
        targetSpan_[j] = {nb.neighbour[nb.offset[j]], nb.neighbour[nb.offset[j + 1] - 1]};
        sources_.push_back(j);
      }
    if (static_cast<Index>(sources_.size()) == n) sources_.clear();  // every particle
#pragma omp parallel for schedule(static)
    for (Index j = 0; j < n; ++j)
      for (Index k = nb.offset[j]; k < nb.offset[j + 1]; ++k) {
        const Index i = nb.neighbour[k];
        const auto first = nb.neighbour.begin() + nb.offset[i];
        const auto last = nb.neighbour.begin() + nb.offset[i + 1];
        const auto at = std::lower_bound(first, last, j);
        if (at == last || *at != j) continue;
        const Index m = static_cast<Index>(at - first);  // J's position in I's list
        if constexpr (Taylor) {
          records[k].template head<D>() = t.row(i)[m];
          records[k].template tail<P>() = T->row(i)[m];
        } else {
          records[k] = t.row(i)[m];
        }
      }
    records_ = SharedRows<Record>(nb, std::move(records));
  }

  // The bytes of the per-pair records the pass streams (each distinct row once).
  double storedPairBytes() const {
    return records_.storedBytes();
  }

  // For the targets (all particles, or the ascending list given): sum_i = own(i) minus the
  // terms of every source J (particle with a list) with i in its list, then finish(i, sum_i). S:
  // the stress sent through t_IJ (padded or plain); R: the hyperstresses (Taylor).
  template <class SM, class Own, class Finish>
  void accumulate(const LargeArray<SM>& S, const LargeArray<PaddedSymMatrix>* R,
                  const std::vector<Index>* targets, const MeetInTheMiddle& split, Own&& own,
                  Finish&& finish) {
    const Index n = nb_.particleCount();
    const Index count = targets ? static_cast<Index>(targets->size()) : n;
    const bool listed = !sources_.empty();
    const Index sourceCount = listed ? static_cast<Index>(sources_.size()) : n;
#pragma omp parallel
    {
#ifdef _OPENMP
      const Index threads = omp_get_num_threads(), thread = omp_get_thread_num();
#else
      const Index threads = 1, thread = 0;
#endif
      // where the pass before met (a static share when it ran over other particles)
      const auto [p0, p1] = split.shareOf(count, thread, threads);
      if (p0 < p1) {
        auto target = [&](Index p) { return targets ? (*targets)[p] : p; };
        const Index a = target(p0), b = p1 < count ? target(p1) : n;  // this thread's targets
        for (Index p = p0; p < p1; ++p)
          sums_[target(p)] = own(target(p));
        for (Index s = 0; s < sourceCount; ++s)
          scatterFrom(listed ? sources_[s] : s, a, b, S, R);
        for (Index p = p0; p < p1; ++p)
          finish(target(p), sums_[target(p)]);
      }
    }
  }

 private:
  // Source j's terms on its targets in [a, b).
  template <class SM>
  void scatterFrom(Index j, Index a, Index b, const LargeArray<SM>& S,
                   const LargeArray<PaddedSymMatrix>* R) {
    constexpr int Rows = SM::RowsAtCompileTime;
    // (the spans: one sequential read per source, where the rows' ends would be two lines)
    if (targetSpan_[j][1] < a || targetSpan_[j][0] >= b) return;
    const Index* neighbour = nb_.neighbour.data();
    const Index start = nb_.offset[j];
    Index k0 = start, k1 = nb_.offset[j + 1];
    while (neighbour[k0] < a)
      ++k0;
    while (neighbour[k1 - 1] >= b)
      --k1;
    SM Sj;
    Sj = S[j];  // assigned, it stays in registers; copy-constructed, GCC staged it on the stack
    [[maybe_unused]] PaddedSymMatrix Rj;
    if constexpr (Taylor) Rj = (*R)[j];
    const Record* record = records_.row(j) + (k0 - start);
    PaddedVec<D>* sums = sums_.data();  // a local: the stores below cannot move it
    for (Index k = k0; k < k1; ++k, ++record) {
      prefetchAhead(record);
      PaddedVec<D>& target = sums[neighbour[k]];
      PaddedVec<D> sum = target;
      // the gather's two subtractions, in its order (6.70; the hyperstress term)
      sum.template head<Rows>().noalias() -= Sj * record->template head<D>();
      if constexpr (Taylor) {
        const PaddedVec<D> hyper = Rj * record->template tail<P>();
        sum.noalias() -= hyper;
      }
      target = sum;
    }
  }

  const NeighbourList& nb_;
  SharedRows<Record> records_;
  std::vector<std::array<Index, 2>> targetSpan_;  // per source: its first and last target
  std::vector<Index> sources_;     // the particles with a list, ascending; empty: all of them
  LargeArray<PaddedVec<D>> sums_;  // per target
};

}  // namespace tlsph
