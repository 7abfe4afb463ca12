#include "io/AtomicFile.hpp"

#include <unistd.h>
#include <fstream>
#include <stdexcept>
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

void writeTextAtomically(const std::filesystem::path& target,
                         std::initializer_list<std::string_view> parts, const std::string& kind) {
  const std::string what = "cannot write " + kind + " file " + target.string();
  try {
    writeAtomically(target, [&](const std::filesystem::path& temporary) {
      std::ofstream out(temporary, std::ios::binary);
      for (const std::string_view part : parts)
        out.write(part.data(), static_cast<std::streamsize>(part.size()));
      out.close();
      if (!out) throw std::runtime_error(what);
    });
  } catch (const std::filesystem::filesystem_error& e) {
    throw std::runtime_error(what + ": " + e.what());
  }
}

}  // namespace tlsph
