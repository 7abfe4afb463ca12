#include "output/VtuSeriesWriter.hpp"

#include <cstdio>
#include <stdexcept>
#include <system_error>

#include "output/VtuFile.hpp"

namespace tlsph {

VtuSeriesWriter::VtuSeriesWriter(std::filesystem::path directory, std::string baseName)
    : directory_(std::move(directory)), baseName_(std::move(baseName)) {
  namespace fs = std::filesystem;
  if (baseName_.empty() || baseName_ == "." || baseName_ == ".." ||
      baseName_.find('/') != std::string::npos)
    throw std::invalid_argument("VTU series base name '" + baseName_ +
                                "' must be a plain file name");
  std::error_code error;
  fs::create_directories(directory_, error);
  if (error || !fs::is_directory(directory_))
    throw std::runtime_error("cannot create output directory " + directory_.string() +
                             (error ? ": " + error.message() : ": not a directory"));
  pvdPath_ = directory_ / (baseName_ + ".pvd");
}

void VtuSeriesWriter::resume(const std::vector<PvdEntry>& frames) {
  entries_ = frames;
  writePvdFile(pvdPath_, entries_);
  std::error_code ignored;
  for (std::size_t k = entries_.size();; ++k) {
    char counter[32];
    std::snprintf(counter, sizeof counter, "_%06zu.vtu", k);
    if (!std::filesystem::remove(directory_ / (baseName_ + counter), ignored)) break;
  }
}

std::filesystem::path VtuSeriesWriter::write(const Frame& frame) {
  char counter[32];
  std::snprintf(counter, sizeof counter, "_%06zu.vtu", entries_.size());
  const std::string name = baseName_ + counter;
  const std::filesystem::path file = directory_ / name;
  writeVtuFile(frame, file);
  // The .pvd sits beside the frames, so the bare file name is the relative path.
  entries_.push_back({frame.time, name});
  writePvdFile(pvdPath_, entries_);
  return file;
}

}  // namespace tlsph
