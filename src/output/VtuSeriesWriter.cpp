#include "output/VtuSeriesWriter.hpp"

#include <cstdio>
#include <stdexcept>
#include <system_error>

#include "output/PvtuFile.hpp"
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

std::string VtuSeriesWriter::frameStem(std::size_t k) const {
  char counter[32];
  std::snprintf(counter, sizeof counter, "_%06zu", k);
  return baseName_ + counter;
}

void VtuSeriesWriter::resume(const std::vector<PvdEntry>& frames, bool owner) {
  entries_ = frames;
  if (!owner) return;
  writePvdFile(pvdPath_, entries_);
  std::error_code ignored;
  for (std::size_t k = entries_.size();; ++k) {
    const std::string stem = frameStem(k);
    const bool whole = std::filesystem::remove(directory_ / (stem + ".vtu"), ignored);
    const bool index = std::filesystem::remove(directory_ / (stem + ".pvtu"), ignored);
    const auto pieces = std::filesystem::remove_all(directory_ / stem, ignored);
    if (!whole && !index && (pieces == 0 || pieces == static_cast<std::uintmax_t>(-1))) break;
  }
}

std::filesystem::path VtuSeriesWriter::write(const Frame& frame) {
  const std::string name = frameStem(entries_.size()) + ".vtu";
  const std::filesystem::path file = directory_ / name;
  writeVtuFile(frame, file);
  // The .pvd sits beside the frames, so the bare file name is the relative path.
  entries_.push_back({frame.time, name});
  writePvdFile(pvdPath_, entries_);
  return file;
}

std::filesystem::path VtuSeriesWriter::writePiece(const Frame& piece, int rank) {
  const std::string stem = frameStem(entries_.size());
  const std::filesystem::path file =
      directory_ / stem / (stem + "_" + std::to_string(rank) + ".vtu");
  writeVtuFile(piece, file);  // creates the frame's directory
  return file;
}

std::filesystem::path VtuSeriesWriter::addPieces(const Frame& layout, int ranks, bool writeIndex) {
  const std::string stem = frameStem(entries_.size());
  const std::filesystem::path file = directory_ / (stem + ".pvtu");
  if (writeIndex) {
    std::vector<std::string> pieces;
    for (int r = 0; r < ranks; ++r)
      pieces.push_back(stem + "/" + stem + "_" + std::to_string(r) + ".vtu");
    writePvtuFile(layout, pieces, file);
  }
  entries_.push_back({layout.time, stem + ".pvtu"});
  if (writeIndex) writePvdFile(pvdPath_, entries_);
  return file;
}

}  // namespace tlsph
