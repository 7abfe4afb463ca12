// Prints a tlsph frame (.vtu, or a distributed run's .pvtu of pieces) as text that is equal
// for equal frames, bit for bit: one line per particle in particle order (by the `id` array
// when there is one, else point order), the position and every point array except `id` as
// hexadecimal floats; first the field data (TIME, STEP) and the arrays' names. The MPI test
// compares a serial run's frames with a distributed run's through it.
#include <vtkDataArray.h>
#include <vtkFieldData.h>
#include <vtkPointData.h>
#include <vtkSmartPointer.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLPUnstructuredGridReader.h>
#include <vtkXMLUnstructuredGridReader.h>

#include <algorithm>
#include <cstdio>
#include <numeric>
#include <string>
#include <vector>

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: frame_dump FRAME.vtu|FRAME.pvtu\n");
    return 2;
  }
  const std::string file = argv[1];
  vtkSmartPointer<vtkXMLReader> reader;
  if (file.size() > 5 && file.substr(file.size() - 5) == ".pvtu")
    reader = vtkSmartPointer<vtkXMLPUnstructuredGridReader>::New();
  else
    reader = vtkSmartPointer<vtkXMLUnstructuredGridReader>::New();
  reader->SetFileName(file.c_str());
  reader->Update();
  auto* grid = vtkUnstructuredGrid::SafeDownCast(reader->GetOutputDataObject(0));
  if (!grid || reader->GetErrorCode() != 0) {
    std::fprintf(stderr, "frame_dump: cannot read %s\n", file.c_str());
    return 1;
  }
  for (const char* name : {"TIME", "STEP"}) {
    vtkDataArray* a = grid->GetFieldData() ? grid->GetFieldData()->GetArray(name) : nullptr;
    std::printf("%s %a\n", name, a && a->GetNumberOfTuples() > 0 ? a->GetComponent(0, 0) : -1.0);
  }
  const vtkIdType n = grid->GetNumberOfPoints();
  vtkPointData* data = grid->GetPointData();
  vtkDataArray* ids = data->GetArray("id");
  std::vector<vtkIdType> order(n);
  std::iota(order.begin(), order.end(), 0);
  if (ids)
    std::sort(order.begin(), order.end(), [&](vtkIdType a, vtkIdType b) {
      return ids->GetComponent(a, 0) < ids->GetComponent(b, 0);
    });
  std::vector<vtkDataArray*> arrays;
  std::printf("points %lld arrays", static_cast<long long>(n));
  for (int k = 0; k < data->GetNumberOfArrays(); ++k)
    if (vtkDataArray* a = data->GetArray(k);
        a && a->GetName() && std::string(a->GetName()) != "id") {
      arrays.push_back(a);
      std::printf(" %s/%d/%s", a->GetName(), a->GetNumberOfComponents(), a->GetDataTypeAsString());
    }
  std::printf("\n");
  for (vtkIdType k = 0; k < n; ++k) {
    const vtkIdType i = order[k];
    if (ids && static_cast<vtkIdType>(ids->GetComponent(i, 0)) != k) {
      std::printf("particle %lld missing or repeated\n", static_cast<long long>(k));
      return 1;
    }
    double x[3];
    grid->GetPoint(i, x);
    std::printf("%a %a %a", x[0], x[1], x[2]);
    for (vtkDataArray* a : arrays)
      for (int c = 0; c < a->GetNumberOfComponents(); ++c)
        std::printf(" %a", a->GetComponent(i, c));
    std::printf("\n");
  }
  return 0;
}
