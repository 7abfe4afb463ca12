// A time series of frames for ParaView: one .vtu per frame plus a .pvd collection that is
// rewritten after every frame, so an interrupted run still leaves a loadable series.
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include "output/Frame.hpp"
#include "output/PvdFile.hpp"

namespace tlsph {

class VtuSeriesWriter {
 public:
  // Creates `directory` (and parents). baseName is a plain file-name stem (no '/').
  // Throws std::invalid_argument for a bad baseName, std::runtime_error naming the directory
  // if it cannot be created. Existing files of an earlier series are overwritten frame by frame.
  VtuSeriesWriter(std::filesystem::path directory, std::string baseName);

  // Writes directory/baseName_NNNNNN.vtu (NNNNNN = frameCount(), zero-padded to 6 digits),
  // then rewrites directory/baseName.pvd listing every frame so far; returns the .vtu path.
  // Both files are replaced atomically. If the .vtu fails nothing is recorded; if only the
  // .pvd fails the frame stays recorded (its file exists) and the next write lists it.
  std::filesystem::path write(const Frame& frame);

  // Continues the series of an interrupted run: the frames written up to its checkpoint are
  // kept (and the .pvd rewritten to list only them); frame files numbered after them, written
  // after the checkpoint, are removed, and the next write() takes the next number.
  void resume(const std::vector<PvdEntry>& frames);
  const std::vector<PvdEntry>& frames() const { return entries_; }

  const std::filesystem::path& directory() const { return directory_; }
  const std::filesystem::path& pvdPath() const { return pvdPath_; }
  std::size_t frameCount() const { return entries_.size(); }

 private:
  std::filesystem::path directory_;
  std::string baseName_;
  std::filesystem::path pvdPath_;
  std::vector<PvdEntry> entries_;
};

}  // namespace tlsph
