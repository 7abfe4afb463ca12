// The Communicator of a distributed run over MPI: the halo exchange of
// HaloExchange, the gather of every rank's particles (MPI_Allgatherv of the owned entries),
// reductions and broadcasts on the communicator given.
#pragma once

#include <mpi.h>

#include <memory>
#include <vector>

#include "distributed/Communicator.hpp"
#include "distributed/HaloExchange.hpp"

namespace tlsph {

class MpiCommunicator final : public Communicator {
 public:
  explicit MpiCommunicator(MPI_Comm comm);

  int rank() const override { return rank_; }
  int size() const override { return size_; }
  void setPartition(const DomainPartition& partition, const NeighbourList& nb) override;
  void exchangeHaloBytes(char* values, std::size_t width) override;
  void gatherAllBytes(char* values, std::size_t width) override;
  void sum(double* values, int count) override;
  void max(double* values, int count) override;
  void broadcastBytes(char* data, std::size_t bytes, int root) override;
  void barrier() override;

  // Particles received per halo exchange on this rank.
  std::size_t haloCount() const { return halo_ ? halo_->haloCount() : 0; }

  // Wall time spent in each kind of operation on this rank since construction (a blocking
  // operation's time includes waiting for the slowest rank), and the bytes received.
  struct Traffic {
    double seconds = 0.0;
    long calls = 0;
    double bytes = 0.0;
  };
  const Traffic& haloTraffic() const { return haloTraffic_; }
  const Traffic& reductionTraffic() const { return reductionTraffic_; }
  const Traffic& gatherTraffic() const { return gatherTraffic_; }

 private:
  MPI_Comm comm_;
  int rank_ = 0, size_ = 1;
  std::unique_ptr<HaloExchange> halo_;
  std::vector<std::vector<Index>> owned_;  // per rank, ascending
  std::vector<char> sendBuffer_, receiveBuffer_;
  Traffic haloTraffic_, reductionTraffic_, gatherTraffic_;
};

// True when this process was started by an MPI launcher (mpirun, srun): then `tlsph run`
// initialises MPI; run directly it stays serial and never touches MPI.
bool launchedByMpi();

}  // namespace tlsph
