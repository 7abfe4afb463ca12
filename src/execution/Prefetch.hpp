// Software prefetch for the pair loops' per-pair streams and gathers.
//
// Each pass reads its per-pair records (the fit [g_IJ, S_IJ], the reverse vectors, X_IJ, c_IJ)
// front to back, a particle's row of about 26-30 records at a time, while it gathers the
// neighbours' values from cache. The hardware prefetchers alone left the passes waiting on
// these streams; asking for the line a fixed distance ahead, once per record, gives +34-46 % per
// step on unshared rows, best at 1.5-2 KB ahead (about one particle's row of the widest, 72 B,
// record; docs/performance.md). Shared rows (SharedRows.hpp), read mostly from cache, run faster
// without it, so a pass asks only where its rows stream (SharedRows::streams).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

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

// The gathers: a pass reads, per pair, the neighbour's per-particle values (S_J, R_J, F_J).
// On a lattice particle i + 1's neighbours are mostly particle i's shifted by one, so the lines
// a particle kGatherAhead further on will read at this pair's position are those of value
// j + kGatherAhead. Out of cache the hardware prefetchers do not follow the several dozen
// streams this makes (one per stencil row and array): asking for them gives +17-39 % at 10^6
// particles but costs 7-9 % when the arrays sit in the last-level cache, hence only where they
// do not (gathersFromMemory).
inline constexpr std::intptr_t kGatherAhead = 8;

// Asks for every cache line of value j + kGatherAhead of the per-particle array a (a hint,
// also past the array's end; integer arithmetic, no out-of-range pointer is formed).
template <class T>
inline void prefetchGather(const T* a, std::intptr_t j) {
#if defined(__GNUC__) || defined(__clang__)
  const std::uintptr_t p = reinterpret_cast<std::uintptr_t>(a) +
                           sizeof(T) * static_cast<std::uintptr_t>(j + kGatherAhead);
  for (std::uintptr_t line = p & ~std::uintptr_t(63); line < p + sizeof(T); line += 64)
    __builtin_prefetch(reinterpret_cast<const void*>(line));
#else
  (void)a;
  (void)j;
#endif
}

// The last-level data cache of this machine in bytes (Linux: the highest level under
// /sys/devices/system/cpu/cpu0/cache, which a virtual machine reports as the guest sees it;
// else the C library's answer; 32 MiB when neither knows). Read once. (Prefetch.cpp)
std::size_t lastLevelCacheBytes();
// "32768K", "1M", "512": a cache size as /sys writes it, in bytes (0 when unreadable).
std::size_t parseCacheSize(const std::string& text);
// True when arrays of this many bytes, gathered by the pair loops, are read from memory rather
// than from the last-level cache (more than twice its size: the prefetch's break-even lies
// between once and three times).
inline bool gathersFromMemory(double gatheredBytes) {
  return gatheredBytes > 2.0 * static_cast<double>(lastLevelCacheBytes());
}

}  // namespace tlsph
