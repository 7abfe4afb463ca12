// Storage for the arrays the pair loops stream every step: the per-pair arrays
// and the per-particle ones they gather at the neighbours' indices. A block of 2 MiB or more
// is mapped on its own, aligned to 2 MiB and advised for transparent huge pages before it is
// first touched, so the kernel backs it with 2 MiB pages where it can.
// Why: the per-pair arrays (tens of MB at 10^4 particles, GB at 10^6) are streamed once per
// pass; on 4 KiB pages each stream takes a TLB miss every 4 KiB (every 57 pairs of the 72 B
// Taylor fit), and under a hypervisor a miss walks two page tables. Most Linux systems leave
// huge pages to programs that ask (THP "madvise"), so a plain std::vector never gets them.
// Where the kernel has them off ("never") or none is free, the pages are ordinary ones: the
// results are the same either way, only the speed differs (docs/performance.md).
// Smaller blocks come from operator new as with std::allocator.
#pragma once

#include <cstddef>
#include <new>
#include <vector>

namespace tlsph {

namespace largepages {
inline constexpr std::size_t kHugePageBytes = std::size_t(2) << 20;
// bytes >= kHugePageBytes: a fresh mapping aligned to kHugePageBytes, advised for huge pages
// (Linux; elsewhere operator new). Throws std::bad_alloc.
void* map(std::size_t bytes);
void unmap(void* p, std::size_t bytes) noexcept;
// The mapping that holds address p, as /proc/self/smaps reports it (Linux; elsewhere all
// zero): whether it is advised for huge pages and how many of its bytes huge pages back now.
// For tests and the benchmark's report.
struct MappingInfo {
  bool found = false;
  bool advised = false;           // VmFlags "hg"
  std::size_t bytes = 0;          // the mapping's size
  std::size_t hugePageBytes = 0;  // AnonHugePages
};
MappingInfo mappingOf(const void* p);
}  // namespace largepages

template <class T>
struct LargePageAllocator {
  using value_type = T;

  LargePageAllocator() = default;
  template <class U>
  LargePageAllocator(const LargePageAllocator<U>&) noexcept {}

  T* allocate(std::size_t n) {
    const std::size_t bytes = n * sizeof(T);
    if (bytes >= largepages::kHugePageBytes) return static_cast<T*>(largepages::map(bytes));
    return static_cast<T*>(::operator new(bytes, std::align_val_t(alignof(T))));
  }
  void deallocate(T* p, std::size_t n) noexcept {
    const std::size_t bytes = n * sizeof(T);
    if (bytes >= largepages::kHugePageBytes)
      largepages::unmap(p, bytes);
    else
      ::operator delete(p, std::align_val_t(alignof(T)));
  }

  friend bool operator==(const LargePageAllocator&, const LargePageAllocator&) { return true; }
};

template <class T>
using LargeArray = std::vector<T, LargePageAllocator<T>>;
// A per-pair array (one entry per neighbour pair, in CSR order).
template <class T>
using PairArray = LargeArray<T>;

}  // namespace tlsph
