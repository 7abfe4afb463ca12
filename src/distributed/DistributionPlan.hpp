// How a distributed run splits the particles among the ranks, made once before the pair data
// is built, and the few whole-body numbers the ranks agree on (the stable step, neighbour
// statistics, the quadratic fit's fall-backs). The trajectory stays bitwise the serial one:
// each rank advances its own particles and reads its halo from their owners.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <iterator>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "distributed/Communicator.hpp"
#include "distributed/DomainPartition.hpp"
#include "method/IntegrationConstraint.hpp"
#include "method/Kernel.hpp"
#include "method/NeighbourList.hpp"
#include "method/ReferenceConfiguration.hpp"
#include "method/TimeStep.hpp"
#include "model/Errors.hpp"
#include "model/Scene.hpp"

namespace tlsph {

// How the particles of a distributed run are split (Solver::partition()).
struct PartitionSummary {
  int ranks = 1;
  std::string method = "single";  // "metis", "bisection" or "single"
  Index halo = 0;                 // particles read from other ranks, summed over the ranks
  double imbalance = 1.0;         // largest rank's pairs + particles over the mean
};

// Neighbours per particle over the whole body.
struct NeighbourStats {
  Index min = 0, max = 0;
  double mean = 0.0;
};

inline NeighbourStats neighbourStatsOf(const NeighbourList& nb) {
  const Index n = nb.particleCount();
  NeighbourStats s;
  s.min = n > 0 ? nb.count(0) : 0;
  for (Index i = 0; i < n; ++i) {
    s.min = std::min(s.min, nb.count(i));
    s.max = std::max(s.max, nb.count(i));
  }
  s.mean = n > 0 ? double(nb.pairCount()) / n : 0.0;
  return s;
}

// The particles the quadratic correction's fit could not serve (ReferenceConfiguration's
// linearFallback), over the whole body: how many, the first, and its neighbour count.
struct FallbackSummary {
  Index count = 0, first = -1, neighbours = 0;
};

// A distributed run's split. The pair data is kept for this rank's particles and halo only.
struct DistributionPlan {
  bool active = false;        // more than one rank
  DomainPartition partition;  // every rank's part and particles; this rank's halo
  std::vector<Index> rows;    // this rank's particles and halo, ascending
  PartitionSummary summary;
  NeighbourStats neighbours;  // of the whole body

  // 1 for the particles of `rank`, 0 for the others.
  std::vector<std::uint8_t> ownedMask(int rank, Index particles) const {
    std::vector<std::uint8_t> mine(static_cast<std::size_t>(particles), 0);
    for (Index i : partition.owned[rank])
      mine[i] = 1;
    return mine;
  }
};

// Splits the particles among the ranks (on rank 0, from the whole neighbour graph, which only
// it builds; broadcast), mirrored ghosts with the particles they follow, so that the chain rule
// of their forces stays on one rank; this rank's halo from its particles' lists; the
// communication plan. Inactive for a serial run.
template <int D>
DistributionPlan planDistribution(const Scene<D>& scene, Communicator* comm, double H) {
  DistributionPlan plan;
  if (!comm || comm->size() <= 1) return plan;
  plan.active = true;
  const auto& X = scene.particles.referencePosition;
  const Index n = scene.particles.size();
  const int rank = comm->rank(), size = comm->size();
  auto& partition = plan.partition;
  std::string method;
  std::vector<double> numbers(5, 0.0);  // halo, imbalance, neighbours min, mean, max
  if (rank == 0) {
    const NeighbourList nb = buildNeighbourList<D>(X, H, scene.periodicBox);
    partition = partitionParticles<D>(X, nb, size);
    std::vector<std::pair<Index, Index>> links;
    for (const auto& m : scene.mirrorGhosts) {
      links.emplace_back(m.ghost, m.mirror);
      if (m.second >= 0) links.emplace_back(m.ghost, m.second);
    }
    keepTogether(partition, links, nb);
    method = partition.method;
    const NeighbourStats s = neighbourStatsOf(nb);
    numbers = {double(partition.haloTotal()), partition.imbalance(nb), double(s.min), s.mean,
               double(s.max)};
  } else {
    partition.part.assign(static_cast<std::size_t>(n), 0);
  }
  comm->broadcast(partition.part);
  comm->broadcast(method);
  comm->broadcast(numbers);
  partition.parts = size;
  partition.method = method;
  partition.owned.assign(size, {});
  partition.halo.assign(size, {});
  for (Index i = 0; i < n; ++i)
    partition.owned[partition.part[i]].push_back(i);
  const auto& own = partition.owned[rank];
  const NeighbourList mine = buildNeighbourRows<D>(X, own, H, scene.periodicBox);
  auto& halo = partition.halo[rank];
  for (Index i : own)
    for (Index k = mine.offset[i]; k < mine.offset[i + 1]; ++k)
      if (partition.part[mine.neighbour[k]] != rank) halo.push_back(mine.neighbour[k]);
  std::sort(halo.begin(), halo.end());
  halo.erase(std::unique(halo.begin(), halo.end()), halo.end());
  comm->setPartition(partition, mine);
  std::merge(own.begin(), own.end(), halo.begin(), halo.end(), std::back_inserter(plan.rows));
  plan.summary = {size, method, static_cast<Index>(numbers[0]), numbers[1]};
  plan.neighbours = {static_cast<Index>(numbers[2]), static_cast<Index>(numbers[4]), numbers[3]};
  return plan;
}

// The pair data: of every particle, or (distributed) of this rank's particles and halo. A
// set-up error on one rank (a singular correction tensor in its rows) is every rank's: they
// all build the whole configuration then, which throws the serial run's message.
template <int D>
ReferenceConfiguration<D> buildPairData(const Scene<D>& scene, const Kernel<D>& kernel,
                                        const DistributionPlan& plan, Communicator* comm) {
  auto build = [&](const std::vector<Index>* rows) {
    return buildSceneReference<D>(scene.particles.referencePosition, scene.particles.volume, kernel,
                                  scene.periodicBox, scene.gradientCorrection, scene.quadrature,
                                  scene.particles.quadratureMoments(), scene.particles.boundaryArea,
                                  scene.particles.boundaryMoment, scene.integrationFilter, rows);
  };
  if (!plan.active) return build(nullptr);
  ReferenceConfiguration<D> ref;
  bool failed = false;
  try {
    ref = build(&plan.rows);
  } catch (const SetupError&) {
    failed = true;
  }
  if (comm->any(failed)) build(nullptr);
  return ref;
}

// The smallest of the ranks' stable steps: the lowest index among equal ratios, as serially;
// the limiting particle's numbers from its rank.
inline StableStep globalStableStep(const StableStep& mine, Communicator& comm) {
  auto ratioOf = [](const StableStep& s) {
    return s.particle < 0
               ? std::numeric_limits<double>::infinity()
               : s.dx / std::sqrt(s.waveSpeed * s.waveSpeed + s.hourglassSpeed * s.hourglassSpeed);
  };
  double best = -ratioOf(mine);
  comm.max(&best, 1);
  double index = ratioOf(mine) == -best ? -double(mine.particle) : -1e300;
  comm.max(&index, 1);
  const bool limiting = mine.particle == Index(-index);
  const double none = -std::numeric_limits<double>::infinity();
  std::array<double, 4> fields = {limiting ? mine.dt : none, limiting ? mine.dx : none,
                                  limiting ? mine.waveSpeed : none,
                                  limiting ? mine.hourglassSpeed : none};
  comm.max(fields.data(), 4);
  return {fields[0], Index(-index), fields[1], fields[2], fields[3]};
}

// The quadratic correction's fall-backs over the whole body; each rank knows its own
// particles' (`mine`, null in a serial run: all of them).
template <int D>
FallbackSummary summariseFallback(const ReferenceConfiguration<D>& ref,
                                  const std::vector<std::uint8_t>* mine, Communicator* comm) {
  const auto& list = ref.linearFallback;
  FallbackSummary summary;
  if (!mine) {
    if (!list.empty())
      summary = {Index(list.size()), list.front(), ref.neighbours.count(list.front())};
    return summary;
  }
  double count = 0.0, first = -1e300;
  for (Index i : list)
    if ((*mine)[i]) {
      ++count;
      first = std::max(first, -double(i));
    }
  comm->sum(&count, 1);
  comm->max(&first, 1);
  if (count == 0) return summary;
  const Index i = Index(-first);
  double neighbours = (*mine)[i] ? ref.neighbours.count(i) : 0.0;
  comm->max(&neighbours, 1);
  return {Index(count), i, Index(neighbours)};
}

}  // namespace tlsph
