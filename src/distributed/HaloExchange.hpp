// The static communication plan of one MPI rank, built once from the partition:
// what it receives from each neighbour rank (its halo, the particles of other ranks its own
// particles read) and what it sends (its particles in their halos), both in ascending global
// index on either side, so no index travels. One exchange is one MPI neighbourhood
// all-to-all over a distributed-graph communicator of the ranks that share a halo.
//
// Arrays are indexed by global particle index for now: a rank fills its own entries, and
// exchange() fills its halo entries with the owners' values, leaving every other entry as it
// was.
#pragma once

#include <mpi.h>

#include <cstring>
#include <type_traits>
#include <vector>

#include "distributed/DomainPartition.hpp"

namespace tlsph {

class HaloExchange {
 public:
  // Every rank passes the same partition (its `part` and `owned`; the halos are found here);
  // its number of parts must be the communicator's size. nb holds at least the lists of this
  // rank's particles: what they read, and (the lists are symmetric) who reads them.
  HaloExchange(MPI_Comm comm, const DomainPartition& partition, const NeighbourList& nb);
  ~HaloExchange();
  HaloExchange(const HaloExchange&) = delete;
  HaloExchange& operator=(const HaloExchange&) = delete;

  std::size_t haloCount() const { return receiveIndex_.size(); }

  // T: plain data (numbers; fixed-size Eigen vectors and matrices, arrays of doubles).
  template <class T>
  void exchange(std::vector<T>& values) {
    static_assert(std::is_trivially_destructible_v<T>);
    exchangeBytes(reinterpret_cast<char*>(values.data()), sizeof(T));
  }
  // values: an array of particles of `size` bytes each.
  void exchangeBytes(char* values, std::size_t size);

 private:
  MPI_Comm graph_ = MPI_COMM_NULL;
  int rank_ = 0;
  std::vector<int> neighbours_;
  // Per neighbour (in neighbours_ order): counts and offsets into the flat index lists.
  std::vector<int> sendCounts_, sendOffsets_, receiveCounts_, receiveOffsets_;
  std::vector<Index> sendIndex_, receiveIndex_;
  std::vector<char> sendBuffer_, receiveBuffer_;
};

}  // namespace tlsph
