// A pass's particles shared among the threads two by two, each pair finishing together however
// the host slows either core (docs/performance.md). Every pair of threads holds the
// static shares of its two threads, [count 2k / T, count (2k + 2) / T); its first thread takes
// chunks of it from the bottom upwards, its second from the top downwards, until they meet.
// Each takes a quarter of what is left (at least kMinChunk particles), so a pair makes a few
// dozen claims per pass, and a chunk is contiguous: the particles a thread computes stay next
// to each other and to the ones it computed the pass before, unlike chunks taken from the far
// end of the other thread's share (measured: that moved as many lines between the cores as
// the wait it saved). With an odd thread count the last thread keeps its static share.
// A pass whose particles are independent of each other (F, the penalty, the gathered force)
// gives the same bits whoever computes a particle; the source-scatter force pass, which needs
// fixed ranges, takes the ranges where the pairs met in the pass before it (shareOf()).
#pragma once

#include <algorithm>
#include <array>
#include <atomic>
#include <cstdint>
#include <vector>

#include "execution/Threads.hpp"
#include "model/Types.hpp"

namespace tlsph {

class MeetInTheMiddle {
  // a pair's unclaimed range [lower, upper), one atomic word on its own cache line
  struct alignas(64) Pair {
    std::atomic<std::uint64_t> unclaimed{0};
  };

 public:
  static constexpr Index kMinChunk = 32;

  // Outside a parallel region, before a pass over [0, count) on the threads the next region has.
  void reset(Index count) {
    const int threads = maxThreads();
    // a Pair cannot move (its atomic), so a larger thread count takes a new vector
    if (static_cast<std::size_t>(threads / 2) > pairs_.size())
      pairs_ = std::vector<Pair>(static_cast<std::size_t>(threads / 2));
    count_ = count;
    threads_ = threads;
    for (int k = 0; k < threads / 2; ++k) {
      const auto [bottom, top] = pairRange(k);
      pairs_[k].unclaimed.store(pack(bottom, top), std::memory_order_relaxed);
    }
  }

  // Inside the region, one per thread: the chunks [a, b) it computes, one after the other.
  // (The passes write this loop out: GCC compiled a helper taking the pass's body as a lambda
  // 10-13 % slower.)
  // From split (reset() for this pass) when given, else the thread's static share.
  class Chunks {
   public:
    Chunks(MeetInTheMiddle* split, Index count) : count_(count) {
      const ThreadSlot slot = threadSlot();
      thread_ = slot.thread;
      threads_ = slot.threads;
      // shared with the other thread of its pair, unless the region is not the one reset() saw
      if (split && split->count_ == count && split->threads_ == threads_ &&
          thread_ / 2 < threads_ / 2)
        pair_ = &split->pairs_[thread_ / 2];
    }

    bool next(Index& a, Index& b) {
      if (!pair_) {
        if (done_) return false;
        done_ = true;
        a = staticBegin(count_, thread_, threads_);
        b = staticBegin(count_, thread_ + 1, threads_);
        return a < b;
      }
      std::uint64_t ends = pair_->unclaimed.load(std::memory_order_relaxed);
      for (;;) {
        const Index bottom = lowerOf(ends), top = upperOf(ends);
        if (bottom >= top) return false;
        const Index size = std::max(kMinChunk, (top - bottom) / 4);
        std::uint64_t rest;
        if (thread_ % 2 == 0) {
          a = bottom;
          b = std::min(top, bottom + size);
          rest = pack(b, top);
        } else {
          a = std::max(bottom, top - size);
          b = top;
          rest = pack(bottom, a);
        }
        // the claims only need to be exclusive: the region's barrier publishes the results
        if (pair_->unclaimed.compare_exchange_weak(ends, rest, std::memory_order_relaxed))
          return true;
      }
    }

   private:
    Pair* pair_ = nullptr;
    Index count_;
    int thread_ = 0, threads_ = 1;
    bool done_ = false;
  };

  // After the pass: thread's contiguous part of [0, count), where its pair met (the static share
  // when the last reset() was for another count or thread count, or for an odd last thread).
  // Each pair's two parts cover its range, so the parts of all threads cover [0, count).
  std::array<Index, 2> shareOf(Index count, int thread, int threads) const {
    const std::array<Index, 2> own = {staticBegin(count, thread, threads),
                                      staticBegin(count, thread + 1, threads)};
    if (count != count_ || threads != threads_ || thread / 2 >= threads / 2) return own;
    const auto [bottom, top] = pairRange(thread / 2);
    const Index met = lowerOf(pairs_[thread / 2].unclaimed.load(std::memory_order_relaxed));
    return thread % 2 == 0 ? std::array<Index, 2>{bottom, met} : std::array<Index, 2>{met, top};
  }

  static Index staticBegin(Index count, int thread, int threads) {
    return static_cast<Index>(std::int64_t(count) * thread / threads);
  }

 private:
  static std::uint64_t pack(Index lower, Index upper) {
    return (std::uint64_t(std::uint32_t(lower)) << 32) | std::uint32_t(upper);
  }
  static Index lowerOf(std::uint64_t ends) { return static_cast<Index>(ends >> 32); }
  static Index upperOf(std::uint64_t ends) { return static_cast<Index>(ends & 0xffffffffu); }
  std::array<Index, 2> pairRange(int k) const {
    return {staticBegin(count_, 2 * k, threads_), staticBegin(count_, 2 * k + 2, threads_)};
  }

  std::vector<Pair> pairs_;
  Index count_ = -1;
  int threads_ = 0;
};

}  // namespace tlsph
