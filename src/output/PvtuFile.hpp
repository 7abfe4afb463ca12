// The index of a frame written in pieces (one per rank of a distributed run): a VTK XML
// parallel unstructured grid (.pvtu) naming the pieces' .vtu files and the arrays they hold.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "output/Frame.hpp"

namespace tlsph {

// Writes `file` atomically. `layout` is any one of the pieces (every piece holds the same
// arrays; its points may be none): the index declares its point arrays (fields as Float64,
// flags as UInt8, `id` as Int64) and Float64 points. pieces: the pieces' file names relative
// to the .pvtu's directory, in piece order. Throws std::invalid_argument for an inconsistent
// layout and std::runtime_error naming the file if it cannot be written.
void writePvtuFile(const Frame& layout, const std::vector<std::string>& pieces,
                   const std::filesystem::path& file);

}  // namespace tlsph
