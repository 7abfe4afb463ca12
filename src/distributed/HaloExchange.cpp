// HaloExchange (see the header).
#include "distributed/HaloExchange.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace tlsph {

HaloExchange::HaloExchange(MPI_Comm comm, const DomainPartition& partition,
                           const NeighbourList& nb) {
  int size = 1;
  MPI_Comm_rank(comm, &rank_);
  MPI_Comm_size(comm, &size);
  if (partition.parts != size)
    throw std::invalid_argument("HaloExchange: a partition into " +
                                std::to_string(partition.parts) + " parts on " +
                                std::to_string(size) + " ranks");
  const auto& part = partition.part;
  // Receive: my halo, by owner. Send: my particles in each other part's halo (those with a
  // neighbour there). Both ascending.
  std::vector<std::vector<Index>> receive(size), send(size);
  for (Index i : partition.owned[rank_])
    for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k) {
      const int q = part[nb.neighbour[k]];
      if (q == rank_) continue;
      receive[q].push_back(nb.neighbour[k]);
      if (send[q].empty() || send[q].back() != i) send[q].push_back(i);
    }
  for (auto& r : receive) {
    std::sort(r.begin(), r.end());
    r.erase(std::unique(r.begin(), r.end()), r.end());
  }
  for (int q = 0; q < size; ++q) {
    if (receive[q].empty() && send[q].empty()) continue;
    neighbours_.push_back(q);
    sendOffsets_.push_back(static_cast<int>(sendIndex_.size()));
    sendCounts_.push_back(static_cast<int>(send[q].size()));
    sendIndex_.insert(sendIndex_.end(), send[q].begin(), send[q].end());
    receiveOffsets_.push_back(static_cast<int>(receiveIndex_.size()));
    receiveCounts_.push_back(static_cast<int>(receive[q].size()));
    receiveIndex_.insert(receiveIndex_.end(), receive[q].begin(), receive[q].end());
  }
  const int degree = static_cast<int>(neighbours_.size());
  MPI_Dist_graph_create_adjacent(comm, degree, neighbours_.data(), MPI_UNWEIGHTED, degree,
                                 neighbours_.data(), MPI_UNWEIGHTED, MPI_INFO_NULL, 0, &graph_);
}

HaloExchange::~HaloExchange() {
  if (graph_ != MPI_COMM_NULL) MPI_Comm_free(&graph_);
}

void HaloExchange::exchangeBytes(char* values, std::size_t size) {
  const int width = static_cast<int>(size);
  std::vector<int> sendCounts(sendCounts_), sendOffsets(sendOffsets_),
      receiveCounts(receiveCounts_), receiveOffsets(receiveOffsets_);
  for (auto* v : {&sendCounts, &sendOffsets, &receiveCounts, &receiveOffsets})
    for (int& x : *v)
      x *= width;
  sendBuffer_.resize(sendIndex_.size() * size);
  receiveBuffer_.resize(receiveIndex_.size() * size);
  for (std::size_t k = 0; k < sendIndex_.size(); ++k)
    std::memcpy(sendBuffer_.data() + k * size, values + sendIndex_[k] * size, size);
  MPI_Neighbor_alltoallv(sendBuffer_.data(), sendCounts.data(), sendOffsets.data(), MPI_BYTE,
                         receiveBuffer_.data(), receiveCounts.data(), receiveOffsets.data(),
                         MPI_BYTE, graph_);
  for (std::size_t k = 0; k < receiveIndex_.size(); ++k)
    std::memcpy(values + receiveIndex_[k] * size, receiveBuffer_.data() + k * size, size);
}

}  // namespace tlsph
