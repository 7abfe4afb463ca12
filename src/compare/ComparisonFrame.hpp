// The comparison as a VTU file for ParaView: one point per body particle at its reference
// position, with the FEM and tlsph values, their difference and its magnitude.
#pragma once

#include <filesystem>

#include "compare/Comparison.hpp"
#include "output/Frame.hpp"

namespace tlsph {

// Points: the body particles' reference positions X. Per compared field F: fem_F (interpolated
// FEM values), tlsph_F, error_F (tlsph - fem) and error_F_magnitude (|error_F|, Euclidean or
// Frobenius); all four are NaN at particles outside the FEM mesh, except tlsph_F. Flags:
// compared (1 inside the FEM mesh). Time and step are the tlsph frame's.
Frame comparisonFrame(const Comparison& c);

// The default output file: compare_<frame stem>_vs_<FEM stem>.vtu next to the tlsph frame.
std::filesystem::path defaultComparisonFile(const Comparison& c);

}  // namespace tlsph
