// Reference-configuration neighbour search: a cell list, built once, stored as full
// (both-direction) compressed-sparse-row lists so each particle gathers its own sums.
#pragma once

#include <vector>

#include "execution/LargePageAllocator.hpp"
#include "model/PeriodicBox.hpp"
#include "model/Types.hpp"

namespace tlsph {

struct NeighbourList {
  std::vector<Index> offset;   // neighbours of I are neighbour[offset[I] .. offset[I+1])
  PairArray<Index> neighbour;  // sorted ascending within each particle

  Index particleCount() const { return static_cast<Index>(offset.size()) - 1; }
  Index pairCount() const { return static_cast<Index>(neighbour.size()); }
  Index count(Index i) const { return offset[i + 1] - offset[i]; }
};

// All J != I with |X_IJ| < supportRadius (minimum image along periodic axes).
// Throws SetupError if a periodic box is shorter than twice the support radius,
// where one pair would have more than one image inside the support.
template <int D>
NeighbourList buildNeighbourList(const std::vector<Vec<D>>& X, double supportRadius,
                                 const PeriodicBox<D>& box = {});

// For each query point, the points within supportRadius (two different sets; list I holds
// indices into `points`). Same periodic rules.
template <int D>
NeighbourList buildNeighbourList(const std::vector<Vec<D>>& queries,
                                 const std::vector<Vec<D>>& points, double supportRadius,
                                 const PeriodicBox<D>& box = {});

// The lists of the particles `rows` only (ascending), each exactly as buildNeighbourList gives
// it; the other particles' lists are empty (the offsets span all of X). For a rank of a
// distributed run that keeps pair data for its own particles and its halo only.
template <int D>
NeighbourList buildNeighbourRows(const std::vector<Vec<D>>& X, const std::vector<Index>& rows,
                                 double supportRadius, const PeriodicBox<D>& box = {});

}  // namespace tlsph
