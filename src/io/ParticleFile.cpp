#include "io/ParticleFile.hpp"

#include "output/VtkErrorLog.hpp"

#include <vtkDataArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLUnstructuredGridReader.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

namespace tlsph {

namespace {

std::string trimmed(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t\r") - b + 1);
}

std::vector<std::string> splitCommas(const std::string& line) {
  std::vector<std::string> cells;
  std::stringstream in(line);
  std::string cell;
  while (std::getline(in, cell, ','))
    cells.push_back(trimmed(cell));
  if (!line.empty() && line.back() == ',') cells.push_back("");
  return cells;
}

template <int D>
std::array<std::string, D + 1> requiredColumns() {
  if constexpr (D == 2)
    return {"x", "y", "volume"};
  else
    return {"x", "y", "z", "volume"};
}

template <int D>
void checkSet(const std::filesystem::path& file, const ParticleFileSet<D>& set,
              const std::vector<std::string>& placeOf) {
  if (set.position.empty())
    throw ParticleFileError(file.string() + ": holds no particle (an empty solid)");
  // Two particles at one place would make a pair with no separation.
  std::vector<std::size_t> order(set.position.size());
  for (std::size_t i = 0; i < order.size(); ++i)
    order[i] = i;
  auto less = [&](std::size_t a, std::size_t b) {
    return std::lexicographical_compare(set.position[a].data(), set.position[a].data() + D,
                                        set.position[b].data(), set.position[b].data() + D);
  };
  std::sort(order.begin(), order.end(), less);
  for (std::size_t k = 1; k < order.size(); ++k)
    if (set.position[order[k]] == set.position[order[k - 1]]) {
      const auto [a, b] = std::minmax(order[k - 1], order[k]);
      throw ParticleFileError(file.string() + ": " + placeOf[b] + " repeats the position of " +
                              placeOf[a] + " (two particles at one place)");
    }
}

template <int D>
ParticleFileSet<D> readCsv(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw ParticleFileError(file.string() + ": cannot open the particle file");
  const auto required = requiredColumns<D>();
  std::array<int, D + 1> column;
  column.fill(-1);
  std::size_t columns = 0;
  bool header = false;
  ParticleFileSet<D> set;
  std::vector<std::string> placeOf;
  std::string line;
  long number = 0;
  while (std::getline(in, line)) {
    ++number;
    const std::string text = trimmed(line);
    if (text.empty() || text[0] == '#') continue;
    const std::string where = file.string() + ":" + std::to_string(number);
    const auto cells = splitCommas(text);
    if (!header) {
      header = true;
      columns = cells.size();
      for (std::size_t c = 0; c < cells.size(); ++c)
        for (std::size_t k = 0; k < required.size(); ++k)
          if (cells[c] == required[k]) {
            if (column[k] >= 0)
              throw ParticleFileError(where + ": the column '" + required[k] +
                                      "' is named twice in the header");
            column[k] = static_cast<int>(c);
          }
      for (std::size_t k = 0; k < required.size(); ++k)
        if (column[k] < 0) {
          std::string list;
          for (const auto& r : required)
            list += (list.empty() ? "" : ", ") + r;
          throw ParticleFileError(where + ": the header has no column '" + required[k] + "' (a " +
                                  std::to_string(D) + "D particle file needs " + list +
                                  ", separated by commas)");
        }
      continue;
    }
    if (cells.size() != columns)
      throw ParticleFileError(where + ": " + std::to_string(cells.size()) +
                              " values, but the header names " + std::to_string(columns) +
                              " columns");
    std::array<double, D + 1> value;
    for (std::size_t k = 0; k < required.size(); ++k) {
      const std::string& cell = cells[static_cast<std::size_t>(column[k])];
      double v = 0.0;
      const auto [end, ec] = std::from_chars(cell.data(), cell.data() + cell.size(), v);
      if (ec != std::errc() || end != cell.data() + cell.size() || cell.empty() ||
          !std::isfinite(v))
        throw ParticleFileError(where + ": " + required[k] + " = '" + cell +
                                "' is not a finite number");
      value[k] = v;
    }
    if (!(value[D] > 0.0))
      throw ParticleFileError(where + ": volume = " + cells[static_cast<std::size_t>(column[D])] +
                              " (every particle's volume must be positive)");
    Vec<D> X;
    for (int a = 0; a < D; ++a)
      X[a] = value[a];
    set.position.push_back(X);
    set.volume.push_back(value[D]);
    placeOf.push_back("line " + std::to_string(number));
  }
  if (!header) throw ParticleFileError(file.string() + ": empty (no header line, no particle)");
  checkSet(file, set, placeOf);
  return set;
}

template <int D>
ParticleFileSet<D> readVtu(const std::filesystem::path& file) {
  {
    std::ifstream probe(file);
    if (!probe) throw ParticleFileError(file.string() + ": cannot open the particle file");
  }
  vtkNew<vtkXMLUnstructuredGridReader> reader;
  reader->SetFileName(file.c_str());
  vtkUnstructuredGrid* grid = nullptr;
  {
    const VtkErrorLog log(reader);
    reader->Update();
    grid = reader->GetOutput();
    if (!log.empty() || grid == nullptr || grid->GetPoints() == nullptr)
      throw ParticleFileError(file.string() +
                              ": not a readable VTK XML unstructured grid (.vtu) with points" +
                              (log.empty() ? std::string() : " (VTK: " + log.text() + ")"));
  }
  const vtkIdType n = grid->GetNumberOfPoints();
  vtkDataArray* volume = grid->GetPointData()->GetArray("volume");
  if (volume == nullptr)
    throw ParticleFileError(file.string() + ": no point array 'volume' (" + std::to_string(n) +
                            " points)");
  if (volume->GetNumberOfComponents() != 1)
    throw ParticleFileError(file.string() + ": the point array 'volume' has " +
                            std::to_string(volume->GetNumberOfComponents()) +
                            " components, expected 1");
  ParticleFileSet<D> set;
  std::vector<std::string> placeOf;
  for (vtkIdType i = 0; i < n; ++i) {
    double x[3];
    grid->GetPoint(i, x);
    const std::string where = "point " + std::to_string(i);
    for (int a = 0; a < 3; ++a)
      if (!std::isfinite(x[a]))
        throw ParticleFileError(file.string() + ": " + where +
                                " has a coordinate that is not "
                                "finite");
    if (D == 2 && x[2] != 0.0)
      throw ParticleFileError(file.string() + ": " + where + " has z = " + std::to_string(x[2]) +
                              " (a 2D particle set lies in the plane z = 0)");
    const double V = volume->GetComponent(i, 0);
    if (!(V > 0.0) || !std::isfinite(V))
      throw ParticleFileError(file.string() + ": " + where + " has volume " + std::to_string(V) +
                              " (every particle's volume must be positive and finite)");
    Vec<D> X;
    for (int a = 0; a < D; ++a)
      X[a] = x[a];
    set.position.push_back(X);
    set.volume.push_back(V);
    placeOf.push_back(where);
  }
  checkSet(file, set, placeOf);
  return set;
}

}  // namespace

template <int D>
ParticleFileSet<D> readParticleFile(const std::filesystem::path& file) {
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  std::error_code ec;
  if (!std::filesystem::exists(file, ec)) throw ParticleFileError(file.string() + ": no such file");
  if (std::filesystem::is_directory(file, ec))
    throw ParticleFileError(file.string() + ": a directory, not a particle file");
  if (ext == ".csv") return readCsv<D>(file);
  if (ext == ".vtu") return readVtu<D>(file);
  throw ParticleFileError(file.string() + ": unknown particle file kind '" + ext +
                          "' (expected .csv or .vtu)");
}

template ParticleFileSet<2> readParticleFile<2>(const std::filesystem::path&);
template ParticleFileSet<3> readParticleFile<3>(const std::filesystem::path&);

}  // namespace tlsph
