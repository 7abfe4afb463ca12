#include "compare/ParticleFrame.hpp"

#include <vtkDataArray.h>
#include <vtkFieldData.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkSmartPointer.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLPUnstructuredGridReader.h>
#include <vtkXMLUnstructuredGridReader.h>

#include <stdexcept>
#include <string>

#include "compare/RunFrame.hpp"
#include "output/VtkErrorLog.hpp"

namespace tlsph {

namespace fs = std::filesystem;

const PointField* ParticleFrame::field(std::string_view name) const {
  for (const auto& f : fields)
    if (f.name == name) return &f;
  return nullptr;
}

ParticleFrame readParticleFrame(const fs::path& file) {
  if (!fs::is_regular_file(file))
    throw std::runtime_error("tlsph frame " + file.string() + " does not exist");
  // A distributed run's frame is an index (.pvtu) of per-rank pieces: VTK's reader appends
  // them in piece order.
  vtkSmartPointer<vtkXMLReader> reader;
  if (lowerExtension(file) == ".pvtu")
    reader = vtkSmartPointer<vtkXMLPUnstructuredGridReader>::New();
  else
    reader = vtkSmartPointer<vtkXMLUnstructuredGridReader>::New();
  VtkErrorLog errors(reader);
  reader->SetFileName(file.c_str());
  reader->Update();
  if (!errors.empty() || reader->GetErrorCode() != 0)
    throw std::runtime_error("cannot read tlsph frame " + file.string() + ": " +
                             (errors.empty() ? "VTK reader failed" : errors.text()));
  vtkUnstructuredGrid* grid = vtkUnstructuredGrid::SafeDownCast(reader->GetOutputDataObject(0));
  if (!grid)
    throw std::runtime_error("tlsph frame " + file.string() + " is not an unstructured grid");
  const vtkIdType n = grid->GetNumberOfPoints();
  if (n == 0) throw std::runtime_error("tlsph frame " + file.string() + " has no particles");

  ParticleFrame frame;
  frame.file = file;
  vtkPointData* pointData = grid->GetPointData();
  for (int a = 0; a < pointData->GetNumberOfArrays(); ++a) {
    vtkDataArray* array = pointData->GetArray(a);
    if (!array || !array->GetName()) continue;
    PointField field{array->GetName(), array->GetNumberOfComponents(), {}};
    field.values.resize(static_cast<std::size_t>(n) * field.components);
    for (vtkIdType i = 0; i < n; ++i)
      for (int c = 0; c < field.components; ++c)
        field.values[i * field.components + c] = array->GetComponent(i, c);
    frame.fields.push_back(std::move(field));
  }

  const PointField* u = frame.field("displacement");
  if (!u)
    throw std::runtime_error(
        "tlsph frame " + file.string() +
        " has no point field 'displacement': compare needs it for the reference positions "
        "X = x - u; add displacement to the scene's [output] fields and run it again");
  if (u->components != 3)
    throw std::runtime_error("tlsph frame " + file.string() + ": 'displacement' has " +
                             std::to_string(u->components) + " components, expected 3");
  frame.reference.resize(n);
  for (vtkIdType i = 0; i < n; ++i) {
    double x[3];
    grid->GetPoint(i, x);
    for (int a = 0; a < 3; ++a)
      frame.reference[i][a] = x[a] - u->values[3 * i + a];
  }

  frame.ghost.assign(n, 0);
  if (const PointField* ghost = frame.field("ghost"); ghost && ghost->components == 1) {
    frame.hasGhostFlags = true;
    for (vtkIdType i = 0; i < n; ++i)
      frame.ghost[i] = ghost->values[i] != 0.0;
  }

  vtkFieldData* fieldData = grid->GetFieldData();
  if (vtkDataArray* time = fieldData ? fieldData->GetArray("TIME") : nullptr;
      time && time->GetNumberOfTuples() > 0)
    frame.time = time->GetComponent(0, 0);
  if (vtkDataArray* step = fieldData ? fieldData->GetArray("STEP") : nullptr;
      step && step->GetNumberOfTuples() > 0)
    frame.step = static_cast<long>(step->GetComponent(0, 0));
  return frame;
}

}  // namespace tlsph
