#include "output/VtuFile.hpp"

#include <vtkCallbackCommand.h>
#include <vtkCellArray.h>
#include <vtkCellType.h>
#include <vtkCommand.h>
#include <vtkDoubleArray.h>
#include <vtkExecutive.h>
#include <vtkFieldData.h>
#include <vtkIdTypeArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkTypeInt64Array.h>
#include <vtkUnsignedCharArray.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLUnstructuredGridWriter.h>

#include <algorithm>
#include <cctype>
#include <set>
#include <stdexcept>
#include <string>

#include "io/AtomicFile.hpp"

namespace tlsph {

namespace {

void checkFrame(const Frame& frame, const std::filesystem::path& file) {
  const std::size_t n = frame.points.size();
  const std::string where = " in frame for " + file.string();
  std::set<std::string> names;
  auto checkName = [&](const std::string& name) {
    if (name.empty()) throw std::invalid_argument("unnamed point array" + where);
    // VTK silently replaces an array of the same name, which would lose data.
    if (!names.insert(name).second)
      throw std::invalid_argument("point array '" + name + "' given twice" + where);
  };
  for (const auto& field : frame.fields) {
    checkName(field.name);
    if (field.components < 1 ||
        field.values.size() != static_cast<std::size_t>(field.components) * n)
      throw std::invalid_argument("field '" + field.name + "' has " +
                                  std::to_string(field.values.size()) + " values for " +
                                  std::to_string(field.components) + " components x " +
                                  std::to_string(n) + " points" + where);
  }
  for (const auto& flags : frame.flags) {
    checkName(flags.name);
    if (flags.values.size() != n)
      throw std::invalid_argument("flags '" + flags.name + "' has " +
                                  std::to_string(flags.values.size()) + " values for " +
                                  std::to_string(n) + " points" + where);
  }
  if (frame.ids) {
    checkName("id");
    if (frame.ids->size() != n)
      throw std::invalid_argument("ids: " + std::to_string(frame.ids->size()) + " values for " +
                                  std::to_string(n) + " points" + where);
  }
}

vtkNew<vtkUnstructuredGrid> makeGrid(const Frame& frame) {
  const auto n = static_cast<vtkIdType>(frame.points.size());
  vtkNew<vtkUnstructuredGrid> grid;

  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();  // the default float would not round-trip positions
  points->SetNumberOfPoints(n);
  for (vtkIdType i = 0; i < n; ++i)
    points->SetPoint(i, frame.points[i].data());
  grid->SetPoints(points);

  // Vertex i is point i: build offsets/connectivity directly rather than n InsertNextCell calls.
  vtkNew<vtkIdTypeArray> offsets;
  vtkNew<vtkIdTypeArray> connectivity;
  offsets->SetNumberOfValues(n + 1);
  connectivity->SetNumberOfValues(n);
  for (vtkIdType i = 0; i < n; ++i) {
    offsets->SetValue(i, i);
    connectivity->SetValue(i, i);
  }
  offsets->SetValue(n, n);
  vtkNew<vtkCellArray> cells;
  cells->SetData(offsets, connectivity);
  grid->SetCells(VTK_VERTEX, cells);

  for (const auto& field : frame.fields) {
    vtkNew<vtkDoubleArray> array;
    array->SetName(field.name.c_str());
    array->SetNumberOfComponents(field.components);
    array->SetNumberOfTuples(n);
    std::copy(field.values.begin(), field.values.end(), array->GetPointer(0));
    grid->GetPointData()->AddArray(array);
  }
  for (const auto& flags : frame.flags) {
    vtkNew<vtkUnsignedCharArray> array;
    array->SetName(flags.name.c_str());
    array->SetNumberOfTuples(n);
    std::copy(flags.values.begin(), flags.values.end(), array->GetPointer(0));
    grid->GetPointData()->AddArray(array);
  }

  if (frame.ids) {
    vtkNew<vtkTypeInt64Array> ids;
    ids->SetName("id");
    ids->SetNumberOfTuples(n);
    std::copy(frame.ids->begin(), frame.ids->end(), ids->GetPointer(0));
    grid->GetPointData()->AddArray(ids);
  }

  vtkNew<vtkDoubleArray> time;
  time->SetName("TIME");
  time->InsertNextValue(frame.time);
  grid->GetFieldData()->AddArray(time);
  vtkNew<vtkTypeInt64Array> step;
  step->SetName("STEP");
  step->InsertNextValue(frame.step);
  grid->GetFieldData()->AddArray(step);
  return grid;
}

// Collects VTK's error messages for the exception instead of letting them go to stderr.
void appendVtkError(vtkObject*, unsigned long, void* clientData, void* callData) {
  auto& errors = *static_cast<std::string*>(clientData);
  std::string message = callData ? static_cast<const char*>(callData) : "";
  // VTK prefixes "ERROR: In <source file>, line N": keep only the message itself.
  if (const auto eol = message.find('\n'); eol != std::string::npos) message.erase(0, eol + 1);
  while (!message.empty() && std::isspace(static_cast<unsigned char>(message.back())))
    message.pop_back();
  if (!errors.empty()) errors += "; ";
  errors += message;
}

}  // namespace

void writeVtuFile(const Frame& frame, const std::filesystem::path& file) {
  checkFrame(frame, file);
  const auto grid = makeGrid(frame);
  try {
    writeAtomically(file, [&](const std::filesystem::path& temporary) {
      std::string errors;
      vtkNew<vtkCallbackCommand> onError;
      onError->SetCallback(appendVtkError);
      onError->SetClientData(&errors);

      vtkNew<vtkXMLUnstructuredGridWriter> writer;
      writer->AddObserver(vtkCommand::ErrorEvent, onError);
      // The pipeline adds a generic "algorithm returned failure" dump: the writer's own
      // message already says why, so keep that one off stderr.
      vtkNew<vtkCallbackCommand> ignore;
      writer->GetExecutive()->AddObserver(vtkCommand::ErrorEvent, ignore);
      writer->SetInputData(grid);
      writer->SetFileName(temporary.c_str());
      writer->SetDataModeToAppended();
      writer->EncodeAppendedDataOff();  // raw binary: base64 would add a third to the size
      writer->SetCompressorTypeToZLib();
      writer->SetHeaderTypeToUInt64();  // block sizes beyond 4 GiB on large runs
      if (writer->Write() != 1 || writer->GetErrorCode() != 0)
        throw std::runtime_error("cannot write VTU file " + file.string() +
                                 (errors.empty() ? std::string() : ": " + errors));
    });
  } catch (const std::filesystem::filesystem_error& e) {
    // Directory creation or the final rename: say which output file it was for.
    throw std::runtime_error("cannot write VTU file " + file.string() + ": " + e.what());
  }
}

}  // namespace tlsph
