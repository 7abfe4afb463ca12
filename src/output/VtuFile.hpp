// A single frame as a VTK XML unstructured grid (.vtu) of vertex cells.
#pragma once

#include <filesystem>

#include "output/Frame.hpp"

namespace tlsph {

// Writes `frame` to `file` atomically: points (Float64), one VTK_VERTEX cell per point so
// ParaView draws them without a glyph filter, fields as Float64 point arrays, flags as UInt8
// point arrays, and field data TIME (Float64) and STEP (Int64) so a lone file keeps its time.
// Binary appended data, zlib-compressed.
// Throws std::invalid_argument for an inconsistent frame (array length, empty or repeated
// name) and std::runtime_error naming the file if it cannot be written.
void writeVtuFile(const Frame& frame, const std::filesystem::path& file);

}  // namespace tlsph
