// No formula of method/: per-pair values stored once per distinct particle row, read by the
// fast passes where the plain loops of method/ read the whole per-pair arrays.
//
// A per-pair array holds, for particle I, the row of its pairs' values a_IJ over its neighbour
// list. On a lattice many particles see the same neighbourhood to the last bit (same offsets,
// same volumes, same material), so their rows of gradient vectors, fits, separations and pair
// coefficients are bitwise equal. SharedRows keeps each distinct row once and lets every
// particle point at its row: the pair loops read the same values as from the full array (a
// result does not change by a bit) while the bytes they stream shrink with the number of
// distinct rows (on the benchmark beam 5,904 distinct rows for 41,728 particles).
// Rows are compared bit for bit (0.0 and -0.0 differ): nothing is rounded or merged by a
// tolerance. T must be plain numbers without padding (doubles, fixed-size Eigen vectors).
#pragma once

#include <cassert>
#include <cstddef>
#include <functional>
#include <string_view>
#include <unordered_map>
#include <utility>
#include <vector>

#include "execution/LargePageAllocator.hpp"
#include "method/NeighbourList.hpp"
#include "model/Types.hpp"

namespace tlsph {

template <class T>
class SharedRows {
 public:
  SharedRows() = default;

  // The rows of full (one value per pair of nb), each distinct row kept once, in the order
  // of its first particle (so a run of particles with distinct rows still streams forward),
  // when that at least halves the values; otherwise the rows are read from full itself, which
  // must then outlive this (the reference configuration's arrays: a copy would add memory for
  // little less traffic).
  SharedRows(const NeighbourList& nb, const PairArray<T>& full) {
    const Plan p = plan(nb, full);
    if (2 * static_cast<std::size_t>(p.stored) <= full.size())
      keep(nb, full, p);
    else
      alias(nb, full, p);
    streams_ = readForward(nb);
  }
  // The same for an array handed over: the distinct rows if any row repeats, else full itself.
  SharedRows(const NeighbourList& nb, PairArray<T>&& full) {
    const Plan p = plan(nb, full);
    if (static_cast<std::size_t>(p.stored) < full.size()) {
      keep(nb, full, p);
    } else {
      values_ = std::move(full);
      alias(nb, values_, p);
      alias_ = nullptr;
    }
    streams_ = readForward(nb);
  }

  // Particle i's row: the value of its m-th pair (in its neighbour list's order) is row(i)[m].
  const T* row(Index i) const {
    assert(static_cast<std::size_t>(i) < start_.size());  // built for these particles
    return (alias_ ? alias_->data() : values_.data()) + start_[i];
  }

  std::size_t distinctRows() const { return rows_; }
  // The values the pair loops read the rows from (all pairs' when no row is shared).
  std::size_t storedValues() const { return alias_ ? alias_->size() : values_.size(); }
  double storedBytes() const { return double(storedValues()) * sizeof(T); }
  // True when the rows are those of the array given, not a copy.
  bool aliases() const { return alias_ != nullptr; }
  // True when a pass over the particles in order reads the values front to back: at least half
  // the particles' rows start where the previous particle's ended (all of them when no row is
  // shared). Only then does asking for the line ahead (prefetchAhead) pay: shared rows jump
  // back to a row read before, mostly still in cache, and the line ahead is one no particle
  // needs soon (+34-46 % per step with unshared rows, 1-3 % slower with the beam's shared
  // ones).
  bool streams() const { return streams_; }

 private:
  struct Plan {
    Index stored = 0;          // values the distinct rows hold
    std::vector<Index> first;  // the first particle of each distinct row
  };

  // Sets start_ (each particle's row in the distinct rows) and returns the plan of those rows.
  // Rows by the hash of their bytes; a hash collision is resolved by comparing the bytes.
  Plan plan(const NeighbourList& nb, const PairArray<T>& full) {
    const Index n = nb.particleCount();
    start_.assign(static_cast<std::size_t>(n), 0);
    std::unordered_multimap<std::size_t, Index> firstOf;
    firstOf.reserve(static_cast<std::size_t>(n));
    Plan p;
    for (Index i = 0; i < n; ++i) {
      const std::string_view bytes = rowBytes(nb, full, i);
      const std::size_t hash = std::hash<std::string_view>{}(bytes);
      Index start = -1;
      auto [first, last] = firstOf.equal_range(hash);
      for (auto it = first; it != last && start < 0; ++it)
        if (rowBytes(nb, full, it->second) == bytes) start = start_[it->second];
      if (start < 0) {
        start = p.stored;
        p.stored += nb.count(i);
        firstOf.emplace(hash, i);
        p.first.push_back(i);
      }
      start_[i] = start;
    }
    return p;
  }
  void keep(const NeighbourList& nb, const PairArray<T>& full, const Plan& p) {
    rows_ = p.first.size();
    values_.reserve(static_cast<std::size_t>(p.stored));
    for (Index i : p.first)
      values_.insert(values_.end(), full.begin() + nb.offset[i], full.begin() + nb.offset[i + 1]);
  }
  void alias(const NeighbourList& nb, const PairArray<T>& full, const Plan& p) {
    rows_ = p.first.size();
    for (Index i = 0; i < nb.particleCount(); ++i)
      start_[i] = nb.offset[i];
    alias_ = &full;
  }

  bool readForward(const NeighbourList& nb) const {
    const Index n = static_cast<Index>(start_.size());
    Index forward = 0;
    for (Index i = 1; i < n; ++i)
      forward += start_[i] == start_[i - 1] + nb.count(i - 1);
    return 2 * forward >= n - 1;
  }

  static std::string_view rowBytes(const NeighbourList& nb, const PairArray<T>& full, Index i) {
    return {reinterpret_cast<const char*>(full.data() + nb.offset[i]),
            sizeof(T) * static_cast<std::size_t>(nb.count(i))};
  }

  PairArray<T> values_;                  // the distinct rows, back to back (or all, handed over)
  const PairArray<T>* alias_ = nullptr;  // or the rows of this array
  std::vector<Index> start_;             // particle i's row starts at start_[i]
  std::size_t rows_ = 0;                 // distinct rows
  bool streams_ = true;                  // see streams()
};

}  // namespace tlsph
