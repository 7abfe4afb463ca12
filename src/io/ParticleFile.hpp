// A particle set read from a file: reference positions and volumes, for bodies that come from
// another tool (a relaxed packing, a mesh's nodes with their lumped volumes).
//
// CSV: a header line naming the columns, then one particle per line; columns separated by
// commas (spaces around them are ignored), lines starting with '#' and empty lines skipped. The
// columns `x`, `y` (2D) or `x`, `y`, `z` (3D) and `volume` are required, in any order; other
// columns are ignored. VTU (VTK XML unstructured grid): the points, with a one-component point
// array `volume`. In 2D the points' z must be zero.
#pragma once

#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "model/Types.hpp"

namespace tlsph {

// What is wrong with a particle file; the message names the file (and the line, for CSV).
class ParticleFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

template <int D>
struct ParticleFileSet {
  std::vector<Vec<D>> position;
  std::vector<double> volume;
};

// Reads a .csv or .vtu file (by extension). Every value must be finite, every volume positive,
// and no two particles may share a position. Throws ParticleFileError.
template <int D>
ParticleFileSet<D> readParticleFile(const std::filesystem::path& file);

extern template ParticleFileSet<2> readParticleFile<2>(const std::filesystem::path&);
extern template ParticleFileSet<3> readParticleFile<3>(const std::filesystem::path&);

}  // namespace tlsph
