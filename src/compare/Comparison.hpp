// `tlsph compare`: a tlsph frame against an FEM solution, field by field, at the particles'
// reference positions. This file runs the comparison; ComparisonReport and ComparisonFrame
// present it.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "compare/FieldComparison.hpp"
#include "compare/RunFrame.hpp"
#include "output/Frame.hpp"

namespace tlsph {

struct CompareRequest {
  std::filesystem::path run;  // a tlsph output directory, a .pvd or a .vtu frame
  std::filesystem::path fem;  // the FEM solution: .vtu or legacy .vtk unstructured grid
  std::string frame;          // "" or "last", or a frame number of the series
  // Fields to compare. Empty: displacement, plus cauchy_stress when both files carry it.
  std::vector<std::string> fields;
  // Array names in the FEM file by comparable field; a field not listed uses its own name.
  std::map<std::string, std::string> femArrays;
};

// One field at the body particles (ghosts left out), in the tlsph layout.
struct ComparedField {
  FieldErrors errors;  // maxIndex counts the body particles (Comparison::frameIndex maps it)
  PointField tlsph;    // at the body particles
  PointField fem;      // interpolated, NaN where the particle is outside the FEM mesh
};

struct Comparison {
  FrameChoice frame;  // which frame of which run
  double time = 0.0;  // the frame's time (NaN if unknown)
  long step = -1;     // the frame's step (-1 if unknown)
  std::filesystem::path femFile;
  long long femPoints = 0, femCells = 0;
  std::array<double, 6> femBounds{};
  double probeTolerance = 0.0;                   // vtkProbeFilter's search tolerance [m]
  std::size_t ghosts = 0;                        // left out
  std::vector<std::size_t> frameIndex;           // body particle -> point id in the frame
  std::vector<std::array<double, 3>> reference;  // body particles' X = x - u
  std::vector<std::uint8_t> inside;              // 1 if in the FEM mesh (compared)
  std::size_t insideCount = 0;
  std::vector<ComparedField> fields;
  std::vector<std::string> notes;     // how fields were read, fields left out
  std::vector<std::string> warnings;  // > 1 % outside the mesh, no ghost flags

  std::size_t bodyParticles() const { return reference.size(); }
};

// Reads both files, interpolates the FEM fields at the body particles' reference positions
// and computes the errors. Writes nothing. Throws std::runtime_error naming the file, the
// field and what was expected for bad input, and if no particle lies inside the FEM mesh.
Comparison compareWithFem(const CompareRequest& request);

}  // namespace tlsph
