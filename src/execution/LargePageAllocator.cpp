#include "execution/LargePageAllocator.hpp"

#include <cstdint>
#include <fstream>
#include <sstream>
#include <string>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace tlsph::largepages {

namespace {
std::size_t roundUp(std::size_t bytes) {
  return (bytes + kHugePageBytes - 1) / kHugePageBytes * kHugePageBytes;
}
}  // namespace

#if defined(__linux__)
void* map(std::size_t bytes) {
  const std::size_t length = roundUp(bytes);
  // Map one huge page more than needed and trim both ends, so the block starts on a 2 MiB
  // boundary (a huge page can only back an aligned 2 MiB range).
  void* raw = mmap(nullptr, length + kHugePageBytes, PROT_READ | PROT_WRITE,
                   MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (raw == MAP_FAILED) throw std::bad_alloc();
  const auto start = reinterpret_cast<std::uintptr_t>(raw);
  const std::uintptr_t aligned = roundUp(start);
  if (aligned > start) munmap(raw, aligned - start);
  const std::uintptr_t end = start + length + kHugePageBytes;
  if (end > aligned + length)
    munmap(reinterpret_cast<void*>(aligned + length), end - aligned - length);
  // Advice only: refused (THP off, an old kernel) the block is ordinary memory.
  madvise(reinterpret_cast<void*>(aligned), length, MADV_HUGEPAGE);
  return reinterpret_cast<void*>(aligned);
}

void unmap(void* p, std::size_t bytes) noexcept {
  munmap(p, roundUp(bytes));
}

MappingInfo mappingOf(const void* p) {
  const auto address = reinterpret_cast<std::uintptr_t>(p);
  std::ifstream smaps("/proc/self/smaps");
  std::string line;
  MappingInfo info;
  bool inside = false;
  while (std::getline(smaps, line)) {
    // A mapping's first line: "from-to perms offset dev inode [path]"; then "Key: value" lines.
    std::uintptr_t from = 0, to = 0;
    char dash = 0;
    std::istringstream head(line);
    if (line.find(':') > line.find(' ') && (head >> std::hex >> from >> dash >> to) &&
        dash == '-') {
      if (inside) break;  // past the mapping we wanted
      inside = from <= address && address < to;
      if (inside) {
        info.found = true;
        info.bytes = to - from;
      }
      continue;
    }
    if (!inside) continue;
    if (line.rfind("AnonHugePages:", 0) == 0) {
      std::istringstream value(line.substr(14));
      std::size_t kib = 0;
      value >> kib;
      info.hugePageBytes = kib * 1024;
    } else if (line.rfind("VmFlags:", 0) == 0) {
      std::istringstream flags(line.substr(8));
      std::string flag;
      while (flags >> flag)
        if (flag == "hg") info.advised = true;
    }
  }
  return info;
}
#else
void* map(std::size_t bytes) {
  return ::operator new(bytes, std::align_val_t(64));
}
void unmap(void* p, std::size_t) noexcept {
  ::operator delete(p, std::align_val_t(64));
}
MappingInfo mappingOf(const void*) {
  return {};
}
#endif

}  // namespace tlsph::largepages
