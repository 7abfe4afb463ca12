#include "compare/FemSolution.hpp"

#include <vtkCellData.h>
#include <vtkDataArray.h>
#include <vtkDoubleArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkProbeFilter.h>
#include <vtkStaticCellLocator.h>
#include <vtkUnstructuredGridReader.h>
#include <vtkXMLUnstructuredGridReader.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "output/VtkErrorLog.hpp"

namespace tlsph {

namespace fs = std::filesystem;

namespace {

template <class Reader>
vtkSmartPointer<vtkUnstructuredGrid> readGrid(const fs::path& file) {
  vtkNew<Reader> reader;
  VtkErrorLog errors(reader);
  reader->SetFileName(file.c_str());
  reader->Update();
  if (!errors.empty() || reader->GetErrorCode() != 0)
    throw std::runtime_error("cannot read FEM file " + file.string() + ": " +
                             (errors.empty() ? "VTK reader failed" : errors.text()));
  return reader->GetOutput();
}

// The array holding `name`: point data first, then cell data.
vtkDataArray* findArray(vtkUnstructuredGrid* grid, const std::string& name, bool* isCellData) {
  if (vtkDataArray* a = grid->GetPointData()->GetArray(name.c_str())) {
    *isCellData = false;
    return a;
  }
  *isCellData = true;
  return grid->GetCellData()->GetArray(name.c_str());
}

}  // namespace

FemSolution::FemSolution(vtkSmartPointer<vtkUnstructuredGrid> grid, fs::path file)
    : grid_(std::move(grid)), file_(std::move(file)) {
  if (!grid_ || grid_->GetNumberOfCells() == 0)
    throw std::runtime_error(
        "FEM file " + file_.string() +
        " has no cells: compare interpolates the FEM fields within the mesh's elements");
}

FemSolution FemSolution::read(const fs::path& file) {
  if (!fs::is_regular_file(file))
    throw std::runtime_error("FEM file " + file.string() + " does not exist");
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext == ".vtu") return FemSolution(readGrid<vtkXMLUnstructuredGridReader>(file), file);
  if (ext == ".vtk") {
    vtkNew<vtkUnstructuredGridReader> probe;
    VtkErrorLog errors(probe);
    probe->SetFileName(file.c_str());
    if (!probe->IsFileUnstructuredGrid())
      throw std::runtime_error(
          "FEM file " + file.string() +
          (errors.empty() ? " is not a legacy VTK UNSTRUCTURED_GRID" : ": " + errors.text()));
    return FemSolution(readGrid<vtkUnstructuredGridReader>(file), file);
  }
  throw std::runtime_error("FEM file " + file.string() +
                           ": expected a VTK XML unstructured grid (.vtu) or a legacy VTK "
                           "unstructured grid (.vtk)");
}

bool FemSolution::hasArray(const std::string& name) const {
  bool cell = false;
  return findArray(grid_, name, &cell) != nullptr;
}

std::string FemSolution::arrayList() const {
  std::string list;
  auto add = [&](vtkDataSetAttributes* data, const char* suffix) {
    for (int a = 0; a < data->GetNumberOfArrays(); ++a)
      if (const char* name = data->GetArrayName(a); name && data->GetArray(a))
        list += (list.empty() ? "" : ", ") + std::string(name) + suffix;
  };
  add(grid_->GetPointData(), "");
  add(grid_->GetCellData(), " (cell)");
  return list.empty() ? "none" : list;
}

std::array<double, 6> FemSolution::bounds() const {
  std::array<double, 6> b;
  grid_->GetBounds(b.data());
  return b;
}

double FemSolution::probeTolerance() const {
  double sum = 0.0;
  const vtkIdType cells = grid_->GetNumberOfCells();
  for (vtkIdType c = 0; c < cells; ++c) {
    double b[6];
    grid_->GetCellBounds(c, b);
    sum += std::sqrt((b[1] - b[0]) * (b[1] - b[0]) + (b[3] - b[2]) * (b[3] - b[2]) +
                     (b[5] - b[4]) * (b[5] - b[4]));
  }
  const double size = sum / static_cast<double>(cells);
  return size > 0.0 ? 1e-6 * size : 1e-12;
}

ProbedFields probeFemFields(const FemSolution& fem,
                            const std::vector<std::array<double, 3>>& points,
                            const std::vector<FemFieldRequest>& requests) {
  vtkUnstructuredGrid* grid = fem.grid();
  const std::string where = "FEM file " + fem.file().string();
  ProbedFields result;

  // The probe's source: the mesh with only the requested arrays, converted to the tlsph
  // layout (interpolation is linear, so converting before or after is the same).
  vtkNew<vtkUnstructuredGrid> source;
  source->CopyStructure(grid);
  for (const auto& request : requests) {
    const ComparableField& field = *request.field;
    bool isCellData = false;
    vtkDataArray* array = findArray(grid, request.array, &isCellData);
    if (!array)
      throw std::runtime_error(where + " has no point or cell array '" + request.array + "' for " +
                               std::string(field.name) + " (its arrays: " + fem.arrayList() +
                               "); name the array with --fem-fields " + std::string(field.name) +
                               "=NAME");
    const int components = array->GetNumberOfComponents();
    if (!acceptsFemLayout(field, components))
      throw std::runtime_error(
          where + ": array '" + request.array + "'" +
          (request.array == field.name ? "" : " (" + std::string(field.name) + ")") + " has " +
          std::to_string(components) + " components, expected " + femLayoutText(field));
    vtkNew<vtkDoubleArray> converted;
    converted->SetName(std::string(field.name).c_str());
    converted->SetNumberOfComponents(field.components);
    const vtkIdType tuples = array->GetNumberOfTuples();
    converted->SetNumberOfTuples(tuples);
    std::vector<double> in(components);
    for (vtkIdType t = 0; t < tuples; ++t) {
      array->GetTuple(t, in.data());
      toTlsphLayout(field, components, in.data(), converted->GetPointer(t * field.components));
    }
    (isCellData ? static_cast<vtkDataSetAttributes*>(source->GetCellData())
                : static_cast<vtkDataSetAttributes*>(source->GetPointData()))
        ->AddArray(converted);
    std::string how;
    if (request.array != field.name) how += "from array '" + request.array + "'";
    if (components != field.components)
      how += std::string(how.empty() ? "" : ", ") +
             (field.components == 9 ? "6 symmetric components (xx yy zz xy yz xz) expanded"
                                    : "2 components, z = 0");
    if (isCellData) how += std::string(how.empty() ? "" : ", ") + "cell data: constant per element";
    if (!how.empty()) result.notes.push_back(std::string(field.name) + ": " + how);
  }

  vtkNew<vtkPoints> probePoints;
  probePoints->SetDataTypeToDouble();
  probePoints->SetNumberOfPoints(static_cast<vtkIdType>(points.size()));
  for (std::size_t i = 0; i < points.size(); ++i)
    probePoints->SetPoint(static_cast<vtkIdType>(i), points[i].data());
  vtkNew<vtkPolyData> input;
  input->SetPoints(probePoints);

  vtkNew<vtkProbeFilter> probe;
  VtkErrorLog errors(probe);
  probe->SetInputData(input);
  probe->SetSourceData(source);
  // A cell locator finds the enclosing cell reliably on graded meshes too (the default
  // closest-point search can miss it).
  vtkNew<vtkStaticCellLocator> locator;
  probe->SetCellLocatorPrototype(locator);
  probe->SetComputeTolerance(false);
  probe->SetTolerance(fem.probeTolerance());
  probe->Update();
  vtkDataSet* output = probe->GetOutput();
  vtkDataArray* mask =
      output ? output->GetPointData()->GetArray(probe->GetValidPointMaskArrayName()) : nullptr;
  if (!errors.empty() || !mask ||
      mask->GetNumberOfTuples() != static_cast<vtkIdType>(points.size()))
    throw std::runtime_error("cannot interpolate the fields of " + where + ": " +
                             (errors.empty() ? "vtkProbeFilter failed" : errors.text()));

  result.inside.resize(points.size());
  for (std::size_t i = 0; i < points.size(); ++i)
    result.inside[i] = mask->GetComponent(static_cast<vtkIdType>(i), 0) != 0.0;
  for (const auto& request : requests) {
    const ComparableField& field = *request.field;
    const std::string name(field.name);
    vtkDataArray* values = output->GetPointData()->GetArray(name.c_str());
    if (!values || values->GetNumberOfComponents() != field.components)
      throw std::runtime_error("cannot interpolate '" + request.array + "' of " + where);
    PointField probed{name, field.components,
                      std::vector<double>(points.size() * field.components)};
    for (std::size_t i = 0; i < points.size(); ++i)
      for (int c = 0; c < field.components; ++c)
        probed.values[i * field.components + c] =
            result.inside[i] ? values->GetComponent(static_cast<vtkIdType>(i), c)
                             : std::numeric_limits<double>::quiet_NaN();
    result.fields.push_back(std::move(probed));
  }
  return result;
}

}  // namespace tlsph
