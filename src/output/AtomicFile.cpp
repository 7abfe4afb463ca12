#include "output/AtomicFile.hpp"

#include <unistd.h>
#include <system_error>

namespace tlsph {

void writeAtomically(const std::filesystem::path& target,
                     const std::function<void(const std::filesystem::path&)>& write) {
  namespace fs = std::filesystem;
  if (target.has_parent_path()) fs::create_directories(target.parent_path());
  const fs::path temporary =
      target.string() + ".tmp-" + std::to_string(static_cast<long>(::getpid()));
  try {
    write(temporary);
    fs::rename(temporary, target);
  } catch (...) {
    std::error_code ignored;
    fs::remove(temporary, ignored);
    throw;
  }
}

}  // namespace tlsph
