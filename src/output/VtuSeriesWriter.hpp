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

  // A frame in pieces (a distributed run: one piece per rank, each holding the ids of its
  // points): every rank writes its piece, directory/baseName_NNNNNN/baseName_NNNNNN_R.vtu
  // (R = rank), then, once all have, every rank calls addPieces. With `writeIndex` (one rank)
  // it writes directory/baseName_NNNNNN.pvtu naming the `ranks` pieces, with `layout`'s arrays
  // (any piece: all hold the same), and rewrites the .pvd listing it; the others only count
  // the frame. Files are replaced atomically; returns the .pvtu path.
  std::filesystem::path writePiece(const Frame& piece, int rank);
  std::filesystem::path addPieces(const Frame& layout, int ranks, bool writeIndex);

  // Continues the series of an interrupted run: the frames written up to its checkpoint are
  // kept, and the next write takes the next number. With `owner` (the one writer of the
  // index files) the .pvd is rewritten to list only them, and frame files numbered after them
  // (whole, index or pieces), written after the checkpoint, are removed.
  void resume(const std::vector<PvdEntry>& frames, bool owner = true);
  const std::vector<PvdEntry>& frames() const { return entries_; }

  const std::filesystem::path& directory() const { return directory_; }
  const std::filesystem::path& pvdPath() const { return pvdPath_; }
  std::size_t frameCount() const { return entries_.size(); }

 private:
  std::filesystem::path directory_;
  std::string baseName_;
  std::filesystem::path pvdPath_;
  std::vector<PvdEntry> entries_;

  std::string frameStem(std::size_t k) const;  // baseName_NNNNNN
};

}  // namespace tlsph
