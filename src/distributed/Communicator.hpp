// What the solver needs from a distributed run, without depending on MPI: the
// particles are split among ranks once (DomainPartition); each rank advances its own ones and
// reads a halo of its neighbours' from their owners. The MPI implementation is
// distributed/MpiCommunicator; a serial run has none (a null Communicator*).
//
// Arrays stay indexed by global particle on every rank: a rank computes its own entries,
// exchangeHalo() brings the entries its particles read (one neighbour layer), gatherAll() every
// entry (for what observes the whole body: series rows, frames, checks, checkpoints).
#pragma once

#include <cstddef>
#include <string>
#include <type_traits>
#include <vector>

#include "distributed/DomainPartition.hpp"
#include "model/Types.hpp"

namespace tlsph {

class Communicator {
 public:
  virtual ~Communicator() = default;
  virtual int rank() const = 0;
  virtual int size() const = 0;

  // Builds the communication plan of a partition (the same `part` on every rank: made on rank
  // 0 and broadcast); nb holds at least the lists of this rank's particles.
  virtual void setPartition(const DomainPartition& partition, const NeighbourList& nb) = 0;

  // Byte-level operations on arrays of `count` particles of `width` bytes each.
  virtual void exchangeHaloBytes(char* values, std::size_t width) = 0;
  virtual void gatherAllBytes(char* values, std::size_t width) = 0;

  virtual void sum(double* values, int count) = 0;  // every rank gets the sums (rank order)
  virtual void max(double* values, int count) = 0;  // every rank gets the maxima
  virtual void broadcastBytes(char* data, std::size_t bytes, int root) = 0;  // root's bytes
  virtual void barrier() = 0;

  // Entries of the halo: set to the owners' values; other entries are left as they were.
  template <class T, class A>
  void exchangeHalo(std::vector<T, A>& values) {
    static_assert(std::is_trivially_destructible_v<T>);  // plain numbers, Eigen fixed-size
    if (!values.empty()) exchangeHaloBytes(reinterpret_cast<char*>(values.data()), sizeof(T));
  }
  // Every entry set to its owner's value.
  template <class T, class A>
  void gatherAll(std::vector<T, A>& values) {
    static_assert(std::is_trivially_destructible_v<T>);  // plain numbers, Eigen fixed-size
    if (!values.empty()) gatherAllBytes(reinterpret_cast<char*>(values.data()), sizeof(T));
  }
  // Rank `root`'s values on every rank (the same size on every rank).
  template <class T>
  void broadcast(std::vector<T>& values, int root = 0) {
    static_assert(std::is_trivially_destructible_v<T>);  // plain numbers, Eigen fixed-size
    if (!values.empty())
      broadcastBytes(reinterpret_cast<char*>(values.data()), values.size() * sizeof(T), root);
  }
  // Rank `root`'s string on every rank.
  void broadcast(std::string& text, int root = 0) {
    std::vector<long> length = {static_cast<long>(text.size())};
    broadcast(length, root);
    text.resize(static_cast<std::size_t>(length[0]));
    if (length[0] > 0) broadcastBytes(text.data(), text.size(), root);
  }
  // The lowest rank with a non-empty `text` (-1 if none); its text on every rank.
  int firstNonEmpty(std::string& text) {
    double first = text.empty() ? -1e300 : -double(rank());
    max(&first, 1);
    if (first < -1e299) return -1;
    const int from = int(-first);
    broadcast(text, from);
    return from;
  }
  // True on every rank when `flag` is true on some rank.
  bool any(bool flag) {
    double v = flag ? 1.0 : 0.0;
    max(&v, 1);
    return v > 0.0;
  }
};

}  // namespace tlsph
