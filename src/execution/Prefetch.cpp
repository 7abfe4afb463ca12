#include "execution/Prefetch.hpp"

#include <unistd.h>

#include <cctype>
#include <fstream>

namespace tlsph {

std::size_t parseCacheSize(const std::string& text) {
  std::size_t value = 0, k = 0;
  while (k < text.size() && std::isdigit(static_cast<unsigned char>(text[k])))
    value = 10 * value + static_cast<std::size_t>(text[k++] - '0');
  if (k == 0) return 0;
  if (k == text.size() || std::isspace(static_cast<unsigned char>(text[k]))) return value;
  switch (text[k]) {
    case 'K':
      return value << 10;
    case 'M':
      return value << 20;
    case 'G':
      return value << 30;
    default:
      return 0;
  }
}

namespace {

std::size_t readLastLevelCache() {
  int bestLevel = 0;
  std::size_t bytes = 0;
  for (int index = 0; index < 16; ++index) {
    const std::string dir = "/sys/devices/system/cpu/cpu0/cache/index" + std::to_string(index);
    std::ifstream levelFile(dir + "/level"), typeFile(dir + "/type"), sizeFile(dir + "/size");
    int level = 0;
    std::string type, size;
    if (!(levelFile >> level) || !(typeFile >> type) || !(sizeFile >> size)) continue;
    if (type == "Instruction" || level <= bestLevel) continue;
    if (const std::size_t b = parseCacheSize(size)) {
      bestLevel = level;
      bytes = b;
    }
  }
  if (bytes) return bytes;
#ifdef _SC_LEVEL3_CACHE_SIZE
  if (const long b = sysconf(_SC_LEVEL3_CACHE_SIZE); b > 0) return static_cast<std::size_t>(b);
#endif
  return std::size_t(32) << 20;
}

}  // namespace

std::size_t lastLevelCacheBytes() {
  static const std::size_t bytes = readLastLevelCache();
  return bytes;
}

}  // namespace tlsph
