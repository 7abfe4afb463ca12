// Software prefetch for the pair loops' per-pair streams (issue 12).
//
// Each pass reads its per-pair records (the fit [g_IJ, S_IJ], the reverse vectors, X_IJ, c_IJ)
// front to back, a particle's row of about 26-30 records at a time, while it gathers the
// neighbours' values from cache. The hardware prefetchers alone left the passes waiting on
// these streams both out of cache and from L3; asking for the line a fixed distance ahead,
// once per record, measured +34-46 % per step at 41,728 particles and +0.5-14 % at 5,312 (both
// corrections, 1 and 2 threads, Intel Xeon model 167), with a broad optimum at 1.5-2 KB ahead
// (tried 0.5-6 KB): about one particle's row of the widest (72 B) record. docs/performance.md
// has the tables.
#pragma once

#include <cstdint>

namespace tlsph {

inline constexpr std::uintptr_t kPrefetchBytes = 2048;

// Asks for the cache line kPrefetchBytes past the record at p (a hint: never faults, also past
// the end of the array; integer arithmetic so no out-of-range pointer is formed).
template <class T>
inline void prefetchAhead(const T* p) {
#if defined(__GNUC__) || defined(__clang__)
  __builtin_prefetch(
      reinterpret_cast<const void*>(reinterpret_cast<std::uintptr_t>(p) + kPrefetchBytes));
#else
  (void)p;
#endif
}

}  // namespace tlsph
