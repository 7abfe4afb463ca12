// An FEM solution on its undeformed mesh, read from a VTK file, and its fields interpolated at
// given reference positions with VTK's vtkProbeFilter (the FEM's own shape functions).
#pragma once

#include <vtkSmartPointer.h>
#include <vtkUnstructuredGrid.h>

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "compare/FieldLayout.hpp"
#include "output/Frame.hpp"

namespace tlsph {

class FemSolution {
 public:
  // Reads a VTK XML unstructured grid (.vtu) or a legacy VTK unstructured grid (.vtk).
  // Throws std::runtime_error naming the file if it is missing, unreadable or has no cells.
  static FemSolution read(const std::filesystem::path& file);
  // Wraps a grid built in memory; `file` is only used in messages.
  FemSolution(vtkSmartPointer<vtkUnstructuredGrid> grid, std::filesystem::path file);

  const std::filesystem::path& file() const { return file_; }
  vtkUnstructuredGrid* grid() const { return grid_; }
  // A point array of that name, or failing that a cell array.
  bool hasArray(const std::string& name) const;
  // Every point and cell array name, for messages: "U, S (cell)".
  std::string arrayList() const;
  // xmin xmax ymin ymax zmin zmax of the mesh.
  std::array<double, 6> bounds() const;
  // The probe's search tolerance: 1e-6 of the mean cell size (cell bounding-box diagonal),
  // so that points on the mesh boundary up to round-off are found.
  double probeTolerance() const;

 private:
  vtkSmartPointer<vtkUnstructuredGrid> grid_;
  std::filesystem::path file_;
};

// One field to take from the FEM file: which comparable field, from which array.
struct FemFieldRequest {
  const ComparableField* field = nullptr;
  std::string array;  // its name in the FEM file (point data, or cell data)
};

struct ProbedFields {
  std::vector<std::uint8_t> inside;  // per point: 1 if it lies in a cell of the FEM mesh
  // One per request, named as the comparable field, in the tlsph layout (3 or 9 components),
  // NaN at points outside the mesh.
  std::vector<PointField> fields;
  // How each array was read, when it is worth saying ("cauchy_stress: FEM array 'S' is cell
  // data: constant per element").
  std::vector<std::string> notes;
};

// Interpolates the requested FEM arrays at `points` (point data with the cells' interpolation
// functions, cell data piecewise constant), after converting them to the tlsph layout. Throws
// std::runtime_error naming the FEM file, the array and what was expected if an array is
// missing or has an unsupported number of components.
ProbedFields probeFemFields(const FemSolution& fem,
                            const std::vector<std::array<double, 3>>& points,
                            const std::vector<FemFieldRequest>& requests);

}  // namespace tlsph
