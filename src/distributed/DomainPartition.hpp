// The particles split among the ranks of a distributed run, once, at set-up: in a
// total-Lagrangian code the neighbour graph never changes, so one partition and one halo plan
// serve the whole run. Each part owns its particles and reads a halo of one neighbour layer
// from the others: the step reads neighbours' displacements (the F pass) and their stresses
// (the force pass), never beyond the neighbour list.
//
// Two partitioners, and the better of the two kept (the smaller halo):
//   METIS (k-way, on the neighbour graph, vertices weighted by their pair count): minimises
//   the edge cut, which is what the halo follows;
//   recursive coordinate bisection: cuts across the longest extent into pieces of equal
//   weight; plane cuts, often as good on boxes and never pathological.
#pragma once

#include <string>
#include <vector>

#include "method/NeighbourList.hpp"
#include "model/Types.hpp"

namespace tlsph {

struct DomainPartition {
  int parts = 1;
  std::string method;                     // "metis", "bisection" or "single"
  std::vector<int> part;                  // part of each particle
  std::vector<std::vector<Index>> owned;  // per part, ascending
  std::vector<std::vector<Index>> halo;   // per part: other parts' particles its own read

  Index haloTotal() const;
  // Largest part's weight (pairs + particles) over the mean: 1 is perfect balance.
  double imbalance(const NeighbourList& nb) const;
};

// Owned lists and halos from `part` (and `parts`).
void completePartition(DomainPartition& p, const NeighbourList& nb);

// Puts the two particles of each link, and so every chain of links, in one part (the part of
// the chain's lowest-index particle), then completes the partition again. Mirrored ghosts are
// linked to the particles they follow: a ghost's motion and the chain rule of its force then
// stay on one rank.
void keepTogether(DomainPartition& p, const std::vector<std::pair<Index, Index>>& links,
                  const NeighbourList& nb);

template <int D>
DomainPartition partitionByBisection(const std::vector<Vec<D>>& X, const NeighbourList& nb,
                                     int parts);

// Throws SetupError when the build has no METIS.
DomainPartition partitionByMetis(const NeighbourList& nb, int parts);
bool haveMetis();

// Both (METIS when available), the one with the smaller total halo kept.
template <int D>
DomainPartition partitionParticles(const std::vector<Vec<D>>& X, const NeighbourList& nb,
                                   int parts);

extern template DomainPartition partitionByBisection<2>(const std::vector<Vec<2>>&,
                                                        const NeighbourList&, int);
extern template DomainPartition partitionByBisection<3>(const std::vector<Vec<3>>&,
                                                        const NeighbourList&, int);
extern template DomainPartition partitionParticles<2>(const std::vector<Vec<2>>&,
                                                      const NeighbourList&, int);
extern template DomainPartition partitionParticles<3>(const std::vector<Vec<3>>&,
                                                      const NeighbourList&, int);

}  // namespace tlsph
