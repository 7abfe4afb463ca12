// A ParaView data collection (.pvd): the list of frame files with their times, which
// ParaView opens as one time-dependent data set.
#pragma once

#include <filesystem>
#include <vector>

namespace tlsph {

struct PvdEntry {
  double time = 0.0;
  std::filesystem::path file;  // as written into the collection: relative to the .pvd's directory
};

// Writes the VTKFile type="Collection" XML atomically, one DataSet per entry in order, times
// in shortest round-trip form. Throws std::runtime_error naming the file on failure.
void writePvdFile(const std::filesystem::path& pvd, const std::vector<PvdEntry>& entries);

}  // namespace tlsph
