// MpiCommunicator (see the header).
#include "distributed/MpiCommunicator.hpp"

#include <chrono>
#include <cstdlib>
#include <cstring>

namespace tlsph {

namespace {

// Adds the wall time of its scope to a Traffic record.
class Timed {
 public:
  Timed(MpiCommunicator::Traffic& t, double bytes) : t_(t), start_(Clock::now()) {
    ++t.calls;
    t.bytes += bytes;
  }
  ~Timed() { t_.seconds += std::chrono::duration<double>(Clock::now() - start_).count(); }

 private:
  using Clock = std::chrono::steady_clock;
  MpiCommunicator::Traffic& t_;
  Clock::time_point start_;
};

}  // namespace

MpiCommunicator::MpiCommunicator(MPI_Comm comm) : comm_(comm) {
  MPI_Comm_rank(comm_, &rank_);
  MPI_Comm_size(comm_, &size_);
}

void MpiCommunicator::setPartition(const DomainPartition& partition, const NeighbourList& nb) {
  halo_ = std::make_unique<HaloExchange>(comm_, partition, nb);
  owned_ = partition.owned;
}

void MpiCommunicator::exchangeHaloBytes(char* values, std::size_t width) {
  if (!halo_) return;
  Timed timed(haloTraffic_, double(halo_->haloCount() * width));
  halo_->exchangeBytes(values, width);
}

void MpiCommunicator::gatherAllBytes(char* values, std::size_t width) {
  if (!halo_) return;
  Timed timed(gatherTraffic_, 0.0);
  std::vector<int> counts(size_), offsets(size_);
  std::size_t total = 0;
  for (int r = 0; r < size_; ++r) {
    counts[r] = static_cast<int>(owned_[r].size() * width);
    offsets[r] = static_cast<int>(total);
    total += owned_[r].size() * width;
  }
  const auto& mine = owned_[rank_];
  sendBuffer_.resize(mine.size() * width);
  for (std::size_t k = 0; k < mine.size(); ++k)
    std::memcpy(sendBuffer_.data() + k * width, values + mine[k] * width, width);
  receiveBuffer_.resize(total);
  gatherTraffic_.bytes += double(total - sendBuffer_.size());
  MPI_Allgatherv(sendBuffer_.data(), counts[rank_], MPI_BYTE, receiveBuffer_.data(), counts.data(),
                 offsets.data(), MPI_BYTE, comm_);
  for (int r = 0; r < size_; ++r) {
    if (r == rank_) continue;
    const char* from = receiveBuffer_.data() + offsets[r];
    for (std::size_t k = 0; k < owned_[r].size(); ++k)
      std::memcpy(values + owned_[r][k] * width, from + k * width, width);
  }
}

void MpiCommunicator::sum(double* values, int count) {
  Timed timed(reductionTraffic_, 8.0 * count);
  MPI_Allreduce(MPI_IN_PLACE, values, count, MPI_DOUBLE, MPI_SUM, comm_);
}

void MpiCommunicator::max(double* values, int count) {
  Timed timed(reductionTraffic_, 8.0 * count);
  MPI_Allreduce(MPI_IN_PLACE, values, count, MPI_DOUBLE, MPI_MAX, comm_);
}

void MpiCommunicator::broadcastBytes(char* data, std::size_t bytes, int root) {
  MPI_Bcast(data, static_cast<int>(bytes), MPI_BYTE, root, comm_);
}

void MpiCommunicator::barrier() {
  MPI_Barrier(comm_);
}

bool launchedByMpi() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_SIZE", "PMI_RANK"})
    if (std::getenv(name)) return true;
  return false;
}

}  // namespace tlsph
