// The internal force (6.70), as method/InternalForce.hpp, with the Taylor quadrature's
// hyperstress force (method/TaylorCorrection.hpp), summed from its sources:
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
//
// In 3D with AVX-512, when the stress is padded (the quadrature's, or P + P^hg; P alone is
// sent unpadded), a source's records are stored two pairs interleaved entry by entry (pairs 2b
// and 2b+1: t_0 t_0' t_1 t_1' t_2 t_2', then T_0 T_0' ... T_5 T_5' with the quadrature), so
// that one 512-bit multiply-add serves two pairs: the source's columns duplicated lane by lane
// (S_0e S_0e S_1e S_1e ...) times one entry of both records (a 128-bit load, repeated), the
// rows of the two targets' terms side by side. Each lane is the one-pair product's lane, the
// same multiply-adds in the same order: the same bits. Half the multiply-adds and record loads
// of pair by pair, for three shuffles per two pairs (the two targets' sums in and out): +3-8 %
// per step at the defaults. Without AVX-512 the records stay one after the other: pair by
// pair, reading them every other entry would only cost (5-9 % slower for the unpadded P).
#pragma once

#include <algorithm>
#include <array>
#include <cassert>
#include <type_traits>
#include <vector>

#include <Eigen/Core>
#if defined(__AVX512F__) && defined(__AVX512DQ__)
#include <immintrin.h>
#endif

#include "execution/LargePageAllocator.hpp"
#include "execution/MeetInTheMiddle.hpp"
#include "execution/Prefetch.hpp"
#include "execution/Threads.hpp"
#include "fast/Padded.hpp"
#include "fast/SharedRows.hpp"
#include "fast/TaylorQuadrature.hpp"
#include "method/NeighbourList.hpp"
#include "model/Types.hpp"

namespace tlsph {

template <int D, bool Taylor>
class InternalForceScatter {
 public:
  static constexpr int P = TaylorQuadrature<D>::P;
  using Sym = typename TaylorQuadrature<D>::Sym;
  using PaddedSymMatrix = typename TaylorQuadrature<D>::PaddedSymMatrix;
  // At source J's m-th pair (target I): t_IJ, and T_IJ with the quadrature.
  using Record = std::conditional_t<Taylor, Eigen::Matrix<double, D + P, 1>, Vec<D>>;
  static constexpr int E = Record::RowsAtCompileTime;  // entries per record
  using RecordPair = std::array<double, 2 * E>;        // two records interleaved
#if defined(__AVX512F__) && defined(__AVX512DQ__)
  static constexpr bool kTwoPairsWide = true;  // the 512-bit form below is compiled
#else
  static constexpr bool kTwoPairsWide = false;
#endif

  // t: the gather's rows of t_IJ (each target's own list); T: those of T_IJ (Taylor only).
  // Pairs whose target has no list (a distributed rank's halo edge) get zero: such targets
  // are not the rank's. paddedStress: accumulate() will be given a padded S (3D with AVX-512:
  // the records are then stored in pairs).
  InternalForceScatter(const NeighbourList& nb, const SharedRows<Vec<D>>& t,
                       const SharedRows<Sym>* T, bool paddedStress)
      : nb_(nb),
        interleaved_(D == 3 && paddedStress && kTwoPairsWide),
        sums_(static_cast<std::size_t>(nb.particleCount()), PaddedVec<D>::Zero()) {
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
    if (interleaved_)
      recordPairs_ = interleaved(nb, records);
    else
      records_ = SharedRows<Record>(nb, std::move(records));
  }

  // The bytes of the per-pair records the pass streams (each distinct row once).
  double storedPairBytes() const {
    return interleaved_ ? recordPairs_.storedBytes() : records_.storedBytes();
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
      const ThreadSlot slot = threadSlot();
      const Index threads = slot.threads, thread = slot.thread;
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
    // (the spans: one sequential read per source, where the rows' ends would be two lines)
    if (targetSpan_[j][1] < a || targetSpan_[j][0] >= b) return;
    const Index* neighbour = nb_.neighbour.data();
    const Index start = nb_.offset[j];
    Index k0 = start, k1 = nb_.offset[j + 1];
    while (neighbour[k0] < a)
      ++k0;
    while (neighbour[k1 - 1] >= b)
      --k1;
    if constexpr (kTwoPairsWide && SM::RowsAtCompileTime == 4)
      if (interleaved_)
        return recordPairs_.streams() ? scatterInterleaved<true>(j, k0, k1, S, R)
                                      : scatterInterleaved<false>(j, k0, k1, S, R);
    assert(!interleaved_);  // the constructor's flag: interleaved only for a padded S
    // the rows' line ahead only where they stream (SharedRows::streams; a branch per pair
    // measured as slow as the prefetch itself)
    records_.streams() ? scatterRecords<true>(j, k0, k1, S, R)
                       : scatterRecords<false>(j, k0, k1, S, R);
  }

  // Pair by pair, each pair's record as it is.
  template <bool Ahead, class SM>
  void scatterRecords(Index j, Index k0, Index k1, const LargeArray<SM>& S,
                      const LargeArray<PaddedSymMatrix>* R) {
    constexpr int Rows = SM::RowsAtCompileTime;
    SM Sj;
    Sj = S[j];  // assigned, it stays in registers; copy-constructed, GCC staged it on the stack
    [[maybe_unused]] PaddedSymMatrix Rj;
    if constexpr (Taylor) Rj = (*R)[j];
    const Index* neighbour = nb_.neighbour.data();
    const Record* record = records_.row(j) + (k0 - nb_.offset[j]);
    PaddedVec<D>* sums = sums_.data();  // a local: the stores below cannot move it
    for (Index k = k0; k < k1; ++k, ++record) {
      if constexpr (Ahead) prefetchAhead(record);
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

#if defined(__AVX512F__) && defined(__AVX512DQ__)
  // The records two by two interleaved (3D, S padded): two pairs per 512-bit multiply-add.
  template <bool Ahead, class SM>
  void scatterInterleaved(Index j, Index k0, Index k1, const LargeArray<SM>& S,
                          const LargeArray<PaddedSymMatrix>* R) {
    const Index* neighbour = nb_.neighbour.data();
    const Index start = nb_.offset[j];
    // entry e of the row's pair m: records[2E (m/2) + 2e + m%2]
    const double* records = recordPairs_.row(j)->data();
    PaddedVec<D>* sums = sums_.data();
    // (the masked forms with a full mask: GCC 12 warns on the plain ones, whose pass-through
    // is an undefined register)
    auto twice = [](const double* c) {  // c0 c1 c2 c3 c0 c1 c2 c3
      return _mm512_maskz_broadcast_f64x4(0xff, _mm256_load_pd(c));
    };
    auto low = [](__m512d v) {
      return _mm512_mask_extractf64x4_pd(_mm256_setzero_pd(), 0xf, v, 0);
    };
    const __m512i duplicate = _mm512_set_epi64(3, 3, 2, 2, 1, 1, 0, 0);
    auto columns = [&](const double* c) {  // c0 c0 c1 c1 c2 c2 c3 c3
      return _mm512_maskz_permutexvar_pd(0xff, duplicate, twice(c));
    };
    const double* sj = S[j].data();
    const __m512d s0 = columns(sj), s1 = columns(sj + 4), s2 = columns(sj + 8);
    [[maybe_unused]] __m512d r0, r1, r2, r3, r4, r5;
    if constexpr (Taylor) {
      const double* rj = (*R)[j].data();
      r0 = columns(rj), r1 = columns(rj + 4), r2 = columns(rj + 8);
      r3 = columns(rj + 12), r4 = columns(rj + 16), r5 = columns(rj + 20);
    }
    const __m512i interleave = _mm512_set_epi64(11, 3, 10, 2, 9, 1, 8, 0);
    const __m512i evens = _mm512_set_epi64(7, 5, 3, 1, 6, 4, 2, 0);
    const __m512i odds = _mm512_set_epi64(6, 4, 2, 0, 7, 5, 3, 1);
    // the sum of a pair outside [k0, k1) beside one inside (never read)
    PaddedVec<D> outside = PaddedVec<D>::Zero();
    const Index m0 = k0 - start;
    const double* x = records + 2 * E * (m0 / 2);
    for (Index k = k0 - m0 % 2; k < k1; k += 2, x += 2 * E) {
      if constexpr (Ahead) {
        prefetchAhead(x);
        if constexpr (Taylor) prefetchAhead(x + 8);
      }
      auto entry = [&](int e) {
        return _mm512_maskz_broadcast_f64x2(0xff, _mm_loadu_pd(x + 2 * e));
      };
      // S_J t_IJ and R_J . T_IJ of both pairs, each lane as the one-pair product's (6.70)
      __m512d a = _mm512_mul_pd(s0, entry(0));
      a = _mm512_fmadd_pd(s1, entry(1), a);
      a = _mm512_fmadd_pd(s2, entry(2), a);
      [[maybe_unused]] __m512d h;
      if constexpr (Taylor) {
        h = _mm512_mul_pd(r0, entry(3));
        h = _mm512_fmadd_pd(r1, entry(4), h);
        h = _mm512_fmadd_pd(r2, entry(5), h);
        h = _mm512_fmadd_pd(r3, entry(6), h);
        h = _mm512_fmadd_pd(r4, entry(7), h);
        h = _mm512_fmadd_pd(r5, entry(8), h);
      }
      double* first = (k >= k0 ? sums[neighbour[k]] : outside).data();
      double* second = (k + 1 < k1 ? sums[neighbour[k + 1]] : outside).data();
      __m512d sum = _mm512_permutex2var_pd(twice(first), interleave, twice(second));
      sum = _mm512_sub_pd(sum, a);  // the gather's order
      if constexpr (Taylor) sum = _mm512_sub_pd(sum, h);
      _mm256_store_pd(first, low(_mm512_maskz_permutexvar_pd(0xff, evens, sum)));
      _mm256_store_pd(second, low(_mm512_maskz_permutexvar_pd(0xff, odds, sum)));
    }
  }
#endif

  // The records of sources' pairs 2b and 2b+1 interleaved entry by entry (an odd row's last
  // record beside zeros), each distinct row of record pairs kept once.
  static SharedRows<RecordPair> interleaved(const NeighbourList& nb,
                                            const PairArray<Record>& records) {
    NeighbourList pairsOfRows;  // the rows of record pairs (only the offsets are read)
    const Index n = nb.particleCount();
    pairsOfRows.offset.assign(static_cast<std::size_t>(n) + 1, 0);
    for (Index j = 0; j < n; ++j)
      pairsOfRows.offset[j + 1] = pairsOfRows.offset[j] + (nb.count(j) + 1) / 2;
    PairArray<RecordPair> stored(static_cast<std::size_t>(pairsOfRows.offset[n]), RecordPair{});
    for (Index j = 0; j < n; ++j)
      for (Index m = 0; m < nb.count(j); ++m)
        for (int e = 0; e < E; ++e)
          stored[pairsOfRows.offset[j] + m / 2][2 * e + m % 2] = records[nb.offset[j] + m][e];
    return SharedRows<RecordPair>(pairsOfRows, std::move(stored));
  }

  const NeighbourList& nb_;
  bool interleaved_;                              // records_ empty, recordPairs_ used
  SharedRows<Record> records_;                    // one pair's record after the other
  SharedRows<RecordPair> recordPairs_;            // or two pairs' interleaved
  std::vector<std::array<Index, 2>> targetSpan_;  // per source: its first and last target
  std::vector<Index> sources_;     // the particles with a list, ascending; empty: all of them
  LargeArray<PaddedVec<D>> sums_;  // per target
};

}  // namespace tlsph
