// A comparison as people read it (a table per field on stdout) and as scripts read it (JSON).
#pragma once

#include <ostream>
#include <string>

#include "compare/Comparison.hpp"

namespace tlsph {

// What was compared with what, then one small table per field: particles compared, relative
// L2 error, RMS and max error (and where), max reference magnitude, max error relative to it.
void printComparison(std::ostream& out, const Comparison& c);

// The same numbers as a JSON object (NaN as null), ending in a newline.
std::string comparisonJson(const Comparison& c);

// Writes comparisonJson(c) to `file` atomically. Throws std::runtime_error naming the file.
void writeComparisonJson(const Comparison& c, const std::filesystem::path& file);

}  // namespace tlsph
