// MeetInTheMiddle: every particle of a pass is computed once, by a thread of the pair whose
// static shares hold it; each pair's two threads end with one contiguous block each, which
// shareOf() reports for the pass after; a slow thread leaves more to its partner.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "execution/MeetInTheMiddle.hpp"

using namespace tlsph;

namespace {

#ifdef _OPENMP
// Runs one pass over [0, count) on `threads` threads; owner[p] is the thread that computed p,
// times[p] how many times it was computed.
struct Pass {
  std::vector<int> owner;
  std::vector<int> times;
};

Pass runPass(MeetInTheMiddle* split, Index count, int threads, int slowThread = -1) {
  omp_set_num_threads(threads);
  if (split) split->reset(count);
  std::vector<std::atomic<int>> times(static_cast<std::size_t>(count));
  std::vector<int> owner(static_cast<std::size_t>(count), -1);
#pragma omp parallel
  {
    MeetInTheMiddle::Chunks chunks(split, count);
    bool first = true;
    for (Index a, b; chunks.next(a, b);) {
      for (Index p = a; p < b; ++p) {
        times[p].fetch_add(1);
        owner[p] = omp_get_thread_num();
      }
      if (first && omp_get_thread_num() == slowThread)
        std::this_thread::sleep_for(std::chrono::milliseconds(200));
      first = false;
    }
  }
  Pass pass{owner, std::vector<int>(times.size())};
  for (std::size_t p = 0; p < times.size(); ++p)
    pass.times[p] = times[p].load();
  return pass;
}
#endif

}  // namespace

#ifdef _OPENMP
TEST(MeetInTheMiddle, EveryParticleOnceInItsPairsRangeAsTwoBlocksThatShareOfReports) {
  for (int threads : {1, 2, 3, 4, 5, 7})
    for (Index count : {0, 1, 2, 31, 32, 33, 100, 1000, 41728}) {
      MeetInTheMiddle split;
      const Pass pass = runPass(&split, count, threads);
      for (Index p = 0; p < count; ++p) {
        ASSERT_EQ(pass.times[p], 1) << "particle " << p << " of " << count << ", " << threads;
        // the thread is one of the pair whose static shares hold p (or the odd last thread)
        const int t = pass.owner[p];
        const int pair = t / 2;
        const bool paired = pair < threads / 2;
        const Index lower = MeetInTheMiddle::staticBegin(count, paired ? 2 * pair : t, threads);
        const Index upper =
            MeetInTheMiddle::staticBegin(count, paired ? 2 * pair + 2 : t + 1, threads);
        ASSERT_TRUE(lower <= p && p < upper) << "particle " << p << " on thread " << t;
      }
      // each thread's particles are the contiguous range shareOf() gives it
      Index covered = 0;
      for (int t = 0; t < threads; ++t) {
        const auto [a, b] = split.shareOf(count, t, threads);
        ASSERT_LE(a, b);
        covered += b - a;
        for (Index p = a; p < b; ++p)
          ASSERT_EQ(pass.owner[p], t) << "particle " << p << " of " << count << ", " << threads;
      }
      EXPECT_EQ(covered, count) << threads << " threads";
    }
}

TEST(MeetInTheMiddle, WithoutASplitEachThreadTakesItsStaticShare) {
  const Index count = 1001;
  for (int threads : {1, 2, 3}) {
    const Pass pass = runPass(nullptr, count, threads);
    for (int t = 0; t < threads; ++t)
      for (Index p = MeetInTheMiddle::staticBegin(count, t, threads);
           p < MeetInTheMiddle::staticBegin(count, t + 1, threads); ++p) {
        ASSERT_EQ(pass.times[p], 1);
        ASSERT_EQ(pass.owner[p], t);
      }
  }
}

TEST(MeetInTheMiddle, ASlowThreadLeavesTheRestToItsPartner) {
  // Thread 1 takes its first chunk (the top quarter of the range) and then stalls for 200 ms;
  // thread 0 starts only after that claim and takes all the rest, where a static split would
  // have left it half.
  const Index count = 100000;
  omp_set_num_threads(2);
  MeetInTheMiddle split;
  split.reset(count);
  std::vector<int> owner(static_cast<std::size_t>(count), -1);
  std::atomic<bool> claimed{false};
  int threads = 0;
#pragma omp parallel
  {
    const int thread = omp_get_thread_num();
    if (thread == 0) {
      threads = omp_get_num_threads();
      while (threads == 2 && !claimed.load())
        std::this_thread::yield();
    }
    MeetInTheMiddle::Chunks chunks(&split, count);
    for (Index a, b; chunks.next(a, b);) {
      for (Index p = a; p < b; ++p)
        owner[p] = thread;
      if (thread == 1 && !claimed.load()) {
        claimed = true;
        std::this_thread::sleep_for(std::chrono::milliseconds(200));
      }
    }
  }
  ASSERT_EQ(threads, 2);
  const auto share0 = split.shareOf(count, 0, 2);
  const auto share1 = split.shareOf(count, 1, 2);
  EXPECT_EQ(share0[0], 0);
  EXPECT_GE(share0[1], count * 7 / 10);
  EXPECT_EQ(share1[1], count);
  EXPECT_LE(share1[1] - share1[0], count * 3 / 10);
  EXPECT_GE(share1[1] - share1[0], count / 4);  // its first chunk
  for (Index p = 0; p < count; ++p)
    ASSERT_EQ(owner[p], p < share0[1] ? 0 : 1) << "particle " << p;
}

TEST(MeetInTheMiddle, ShareOfAnotherPassIsTheStaticShare) {
  MeetInTheMiddle split;
  runPass(&split, 1000, 2, 1);  // met far from the middle
  const auto halfOf999 = split.shareOf(999, 0, 2);
  EXPECT_EQ(halfOf999[0], 0);
  EXPECT_EQ(halfOf999[1], 499);
  const auto thirdOf1000 = split.shareOf(1000, 1, 3);
  EXPECT_EQ(thirdOf1000[0], 333);
  EXPECT_EQ(thirdOf1000[1], 666);
}
#endif
