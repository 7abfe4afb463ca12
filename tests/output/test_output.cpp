// The output writers: VTU frames and the PVD collection read back through VTK exactly as
// written, CSV series round-trip, and every file appears whole or not at all.
#include <gtest/gtest.h>
#include <unistd.h>

#include <vtkCellData.h>
#include <vtkCellType.h>
#include <vtkDataArray.h>
#include <vtkDoubleArray.h>
#include <vtkFieldData.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkUnsignedCharArray.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLDataElement.h>
#include <vtkXMLDataParser.h>
#include <vtkXMLPUnstructuredGridReader.h>
#include <vtkXMLUnstructuredGridReader.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <random>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "output/CsvSeries.hpp"
#include "output/Frame.hpp"
#include "output/VtuFile.hpp"
#include "output/VtuSeriesWriter.hpp"

using namespace tlsph;
namespace fs = std::filesystem;

namespace {

// A fresh directory per test, removed (permissions restored first) at the end.
class OutputTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::random_device seed;
    dir_ = fs::temp_directory_path() /
           ("tlsph_test_output_" + std::to_string(::getpid()) + "_" + std::to_string(seed()));
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ignored;
    fs::permissions(dir_ / "series", fs::perms::owner_all, fs::perm_options::add, ignored);
    fs::remove_all(dir_, ignored);
  }
  fs::path dir_;
};

std::set<std::string> filesIn(const fs::path& dir) {
  std::set<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir))
    names.insert(entry.path().filename());
  return names;
}

std::string readText(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// Values chosen to need all 17 significant digits, plus a few awkward ones.
Frame makeFrame(int k, int n) {
  std::mt19937 rng(100 + k);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  Frame frame;
  frame.time = 0.1 * (k + 1);  // 0.30000000000000004 for k = 2
  frame.step = 1000L * k + 7;
  PointField vonMises{"von_mises", 1, {}};
  PointField displacement{"displacement", 3, {}};
  PointField stress{"cauchy_stress", 9, {}};
  PointFlags ghost{"ghost", {}};
  for (int i = 0; i < n; ++i) {
    frame.points.push_back({unit(rng), unit(rng), i % 2 ? 0.0 : unit(rng) * 1e-9});
    vonMises.values.push_back(i == 0 ? 5e-324 : std::exp(30.0 * unit(rng)));
    for (int a = 0; a < 3; ++a)
      displacement.values.push_back(i == 1 ? -0.0 : unit(rng) / 3.0);
    for (int a = 0; a < 9; ++a)
      stress.values.push_back(1e8 * unit(rng));
    ghost.values.push_back(static_cast<std::uint8_t>(i % 3 == 0 ? 1 : i % 7));
  }
  frame.fields = {vonMises, displacement, stress};
  frame.flags = {ghost};
  return frame;
}

void expectSameValues(vtkDataArray* array, const PointField& field) {
  ASSERT_NE(array, nullptr) << field.name;
  ASSERT_NE(vtkDoubleArray::SafeDownCast(array), nullptr) << field.name << " is not Float64";
  ASSERT_EQ(array->GetNumberOfComponents(), field.components) << field.name;
  const auto* values = vtkDoubleArray::SafeDownCast(array)->GetPointer(0);
  ASSERT_EQ(static_cast<std::size_t>(array->GetNumberOfValues()), field.values.size());
  for (std::size_t v = 0; v < field.values.size(); ++v) {
    EXPECT_EQ(values[v], field.values[v]) << field.name << " value " << v;
    EXPECT_EQ(std::signbit(values[v]), std::signbit(field.values[v])) << field.name << " " << v;
  }
}

void expectVtuHolds(const fs::path& file, const Frame& frame) {
  vtkNew<vtkXMLUnstructuredGridReader> reader;
  reader->SetFileName(file.c_str());
  reader->Update();
  ASSERT_EQ(reader->GetErrorCode(), 0u) << file;
  vtkUnstructuredGrid* grid = reader->GetOutput();
  const auto n = static_cast<vtkIdType>(frame.points.size());
  ASSERT_EQ(grid->GetNumberOfPoints(), n);
  ASSERT_EQ(grid->GetNumberOfCells(), n);
  for (vtkIdType i = 0; i < n; ++i) {
    EXPECT_EQ(grid->GetCellType(i), VTK_VERTEX);
    ASSERT_EQ(grid->GetCell(i)->GetNumberOfPoints(), 1);
    EXPECT_EQ(grid->GetCell(i)->GetPointId(0), i);
    double x[3];
    grid->GetPoint(i, x);
    for (int a = 0; a < 3; ++a)
      EXPECT_EQ(x[a], frame.points[i][a]) << "point " << i;
  }
  EXPECT_EQ(grid->GetPoints()->GetDataType(), VTK_DOUBLE);

  vtkPointData* pd = grid->GetPointData();
  EXPECT_EQ(pd->GetNumberOfArrays(), static_cast<int>(frame.fields.size() + frame.flags.size()));
  for (const auto& field : frame.fields)
    expectSameValues(pd->GetArray(field.name.c_str()), field);
  for (const auto& flags : frame.flags) {
    auto* array = vtkUnsignedCharArray::SafeDownCast(pd->GetArray(flags.name.c_str()));
    ASSERT_NE(array, nullptr) << flags.name << " missing or not UInt8";
    ASSERT_EQ(array->GetNumberOfComponents(), 1);
    ASSERT_EQ(array->GetNumberOfTuples(), n);
    for (vtkIdType i = 0; i < n; ++i)
      EXPECT_EQ(array->GetValue(i), flags.values[i]);
  }

  vtkFieldData* fd = grid->GetFieldData();
  vtkDataArray* time = fd->GetArray("TIME");
  ASSERT_NE(time, nullptr);
  ASSERT_EQ(time->GetNumberOfTuples(), 1);
  EXPECT_EQ(time->GetTuple1(0), frame.time);
  vtkDataArray* step = fd->GetArray("STEP");
  ASSERT_NE(step, nullptr);
  EXPECT_EQ(step->GetTuple1(0), static_cast<double>(frame.step));
}

struct PvdDataSet {
  double time;
  std::string file;
};

// The collection through VTK's XML parser (VTK 9.1 has no vtkXMLCollectionReader: that class
// lives in ParaView, whose PVD reader derives from it).
std::vector<PvdDataSet> readPvd(const fs::path& pvd) {
  vtkNew<vtkXMLDataParser> parser;
  parser->SetFileName(pvd.c_str());
  if (parser->Parse() != 1) throw std::runtime_error("unparsable " + pvd.string());
  vtkXMLDataElement* root = parser->GetRootElement();
  EXPECT_STREQ(root->GetName(), "VTKFile");
  EXPECT_STREQ(root->GetAttribute("type"), "Collection");
  vtkXMLDataElement* collection = root->FindNestedElementWithName("Collection");
  if (!collection) throw std::runtime_error("no Collection in " + pvd.string());
  std::vector<PvdDataSet> dataSets;
  for (int e = 0; e < collection->GetNumberOfNestedElements(); ++e) {
    vtkXMLDataElement* dataSet = collection->GetNestedElement(e);
    EXPECT_STREQ(dataSet->GetName(), "DataSet");
    EXPECT_STREQ(dataSet->GetAttribute("part"), "0");
    dataSets.push_back(
        {std::stod(dataSet->GetAttribute("timestep")), dataSet->GetAttribute("file")});
  }
  return dataSets;
}

}  // namespace

TEST_F(OutputTest, VtuFramesReadBackExactly) {
  VtuSeriesWriter writer(dir_ / "series", "beam");
  EXPECT_TRUE(fs::is_directory(dir_ / "series"));
  std::vector<Frame> frames;
  for (int k = 0; k < 3; ++k) {
    frames.push_back(makeFrame(k, 50));
    const fs::path file = writer.write(frames.back());
    char expected[32];
    std::snprintf(expected, sizeof expected, "beam_%06d.vtu", k);
    EXPECT_EQ(file, dir_ / "series" / expected);
    EXPECT_EQ(writer.frameCount(), static_cast<std::size_t>(k + 1));
  }
  for (int k = 0; k < 3; ++k) {
    char name[32];
    std::snprintf(name, sizeof name, "beam_%06d.vtu", k);
    SCOPED_TRACE(name);
    expectVtuHolds(dir_ / "series" / name, frames[k]);
  }
  // Binary appended and zlib-compressed, as requested of the writer.
  const std::string text = readText(dir_ / "series" / "beam_000000.vtu");
  EXPECT_NE(text.find("compressor=\"vtkZLibDataCompressor\""), std::string::npos);
  EXPECT_NE(text.find("<AppendedData encoding=\"raw\">"), std::string::npos);
}

TEST_F(OutputTest, PvdListsEveryFrameWithItsTime) {
  VtuSeriesWriter writer(dir_ / "series", "beam");
  EXPECT_EQ(writer.pvdPath(), dir_ / "series" / "beam.pvd");
  std::vector<double> times;
  for (int k = 0; k < 3; ++k) {
    const Frame frame = makeFrame(k, 50);
    times.push_back(frame.time);
    writer.write(frame);
    EXPECT_EQ(readPvd(writer.pvdPath()).size(), static_cast<std::size_t>(k + 1));
  }
  const auto dataSets = readPvd(writer.pvdPath());
  ASSERT_EQ(dataSets.size(), 3u);
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_EQ(dataSets[k].time, times[k]);  // exact: 0.30000000000000004 must survive
    const fs::path file = writer.pvdPath().parent_path() / dataSets[k].file;
    EXPECT_TRUE(fs::path(dataSets[k].file).is_relative());
    EXPECT_TRUE(fs::is_regular_file(file)) << file;
    vtkNew<vtkXMLUnstructuredGridReader> reader;
    reader->SetFileName(file.c_str());
    reader->Update();
    EXPECT_EQ(reader->GetOutput()->GetFieldData()->GetArray("TIME")->GetTuple1(0), times[k]);
  }
}

TEST_F(OutputTest, WritesLeaveNoTemporariesAndFailuresNoPartialFiles) {
  const fs::path series = dir_ / "series";
  {
    VtuSeriesWriter writer(series, "beam");
    for (int k = 0; k < 3; ++k)
      writer.write(makeFrame(k, 50));
    EXPECT_EQ(filesIn(series), (std::set<std::string>{"beam.pvd", "beam_000000.vtu",
                                                      "beam_000001.vtu", "beam_000002.vtu"}));

    // An invalid frame is refused before anything is written.
    Frame bad = makeFrame(3, 50);
    bad.fields[1].values.pop_back();
    EXPECT_THROW(writer.write(bad), std::invalid_argument);
    bad = makeFrame(3, 50);
    bad.flags.push_back(bad.flags[0]);  // repeated name: VTK would keep only one
    EXPECT_THROW(writer.write(bad), std::invalid_argument);
    EXPECT_EQ(writer.frameCount(), 3u);
    EXPECT_EQ(filesIn(series).size(), 4u);

    // Not root: a read-only directory refuses the write.
    if (::geteuid() != 0) {
      fs::permissions(series,
                      fs::perms::owner_write | fs::perms::group_write | fs::perms::others_write,
                      fs::perm_options::remove);
      EXPECT_THROW(writer.write(makeFrame(3, 50)), std::runtime_error);
      fs::permissions(series, fs::perms::owner_write, fs::perm_options::add);
      EXPECT_EQ(writer.frameCount(), 3u);
      EXPECT_EQ(filesIn(series).size(), 4u);
    }

    // The directory replaced by a regular file.
    fs::remove_all(series);
    std::ofstream(series) << "not a directory";
    try {
      writer.write(makeFrame(3, 50));
      ADD_FAILURE() << "write into a file did not throw";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(series.string()), std::string::npos) << e.what();
    }
    EXPECT_EQ(writer.frameCount(), 3u);
    EXPECT_EQ(readText(series), "not a directory");
  }

  // A parent that is a regular file: the constructor cannot create the directory.
  try {
    VtuSeriesWriter writer(series / "sub", "beam");
    ADD_FAILURE() << "directory under a file did not throw";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find((series / "sub").string()), std::string::npos) << e.what();
  }
  fs::remove(series);

  // VTK itself failing to open its file (name too long, even for root): reported, no debris.
  {
    VtuSeriesWriter writer(series, std::string(250, 'a'));
    try {
      writer.write(makeFrame(0, 50));
      ADD_FAILURE() << "over-long file name did not throw";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("_000000.vtu"), std::string::npos) << e.what();
    }
    EXPECT_EQ(writer.frameCount(), 0u);
    EXPECT_TRUE(filesIn(series).empty());
  }

  // Only the .pvd failing: the frame exists and is listed by the next successful write.
  {
    VtuSeriesWriter writer(series, "beam");
    fs::create_directories(series / "beam.pvd" / "blocker");
    EXPECT_THROW(writer.write(makeFrame(0, 5)), std::runtime_error);
    EXPECT_EQ(writer.frameCount(), 1u);
    fs::remove_all(series / "beam.pvd");
    writer.write(makeFrame(1, 5));
    EXPECT_EQ(readPvd(writer.pvdPath()).size(), 2u);
    EXPECT_EQ(filesIn(series),
              (std::set<std::string>{"beam.pvd", "beam_000000.vtu", "beam_000001.vtu"}));
  }
}

namespace {

// The points of `whole` in `particles` (ascending), with their ids: one rank's piece.
Frame pieceOf(const Frame& whole, const std::vector<std::int64_t>& particles) {
  Frame piece;
  piece.time = whole.time;
  piece.step = whole.step;
  piece.ids = particles;
  for (const std::int64_t i : particles)
    piece.points.push_back(whole.points[i]);
  for (const auto& field : whole.fields) {
    PointField f{field.name, field.components, {}};
    for (const std::int64_t i : particles)
      for (int c = 0; c < field.components; ++c)
        f.values.push_back(field.values[i * field.components + c]);
    piece.fields.push_back(f);
  }
  for (const auto& flags : whole.flags) {
    PointFlags f{flags.name, {}};
    for (const std::int64_t i : particles)
      f.values.push_back(flags.values[i]);
    piece.flags.push_back(f);
  }
  return piece;
}

}  // namespace

// A distributed run's frame: one piece per rank and a .pvtu naming them. VTK's parallel reader
// gives back every point with its id; put in id order they are the whole frame, bit for bit.
// A rank without points still writes its piece, with every array.
TEST_F(OutputTest, FramesInPiecesReadBackAsTheWholeFrame) {
  VtuSeriesWriter writer(dir_ / "series", "beam");
  const int ranks = 3;
  std::vector<std::vector<std::int64_t>> owned(ranks);
  for (int i = 0; i < 40; ++i)
    owned[i % 7 < 3 ? 0 : 1].push_back(i);  // rank 2 owns nothing
  std::vector<Frame> wholes;
  for (int k = 0; k < 2; ++k) {
    wholes.push_back(makeFrame(k, 40));
    std::vector<Frame> pieces;
    for (int r = 0; r < ranks; ++r) {
      pieces.push_back(pieceOf(wholes.back(), owned[r]));
      char name[64];
      std::snprintf(name, sizeof name, "beam_%06d/beam_%06d_%d.vtu", k, k, r);
      EXPECT_EQ(writer.writePiece(pieces.back(), r), dir_ / "series" / name);
    }
    EXPECT_EQ(writer.frameCount(), static_cast<std::size_t>(k));  // not counted before the index
    EXPECT_EQ(writer.addPieces(pieces[2], ranks, true),
              dir_ / "series" / ("beam_00000" + std::to_string(k) + ".pvtu"));
  }
  EXPECT_EQ(filesIn(dir_ / "series"),
            (std::set<std::string>{"beam.pvd", "beam_000000", "beam_000000.pvtu", "beam_000001",
                                   "beam_000001.pvtu"}));
  const auto dataSets = readPvd(writer.pvdPath());
  ASSERT_EQ(dataSets.size(), 2u);
  EXPECT_EQ(dataSets[1].file, "beam_000001.pvtu");
  EXPECT_EQ(dataSets[1].time, wholes[1].time);
  const std::string index = readText(dir_ / "series" / "beam_000001.pvtu");
  EXPECT_NE(index.find("<PDataArray type=\"Int64\" Name=\"id\""), std::string::npos) << index;
  EXPECT_NE(index.find("<Piece Source=\"beam_000001/beam_000001_2.vtu\"/>"), std::string::npos);

  for (int k = 0; k < 2; ++k) {
    SCOPED_TRACE(k);
    vtkNew<vtkXMLPUnstructuredGridReader> reader;
    reader->SetFileName((dir_ / "series" / dataSets[k].file).c_str());
    reader->Update();
    ASSERT_EQ(reader->GetErrorCode(), 0u);
    vtkUnstructuredGrid* grid = reader->GetOutput();
    ASSERT_EQ(grid->GetNumberOfPoints(), 40);
    vtkDataArray* ids = grid->GetPointData()->GetArray("id");
    ASSERT_NE(ids, nullptr);
    EXPECT_EQ(ids->GetDataTypeSize(), 8);
    // Back in particle order, as one frame (the whole frame has no ids).
    Frame merged;
    merged.time = grid->GetFieldData()->GetArray("TIME")->GetTuple1(0);
    merged.step = static_cast<long>(grid->GetFieldData()->GetArray("STEP")->GetTuple1(0));
    merged.points.resize(40);
    std::vector<vtkIdType> at(40, -1);
    for (vtkIdType p = 0; p < 40; ++p) {
      const auto i = static_cast<vtkIdType>(ids->GetComponent(p, 0));
      ASSERT_TRUE(i >= 0 && i < 40 && at[i] < 0) << "id " << i;
      at[i] = p;
      grid->GetPoint(p, merged.points[i].data());
    }
    EXPECT_EQ(merged.points, wholes[k].points);
    EXPECT_EQ(merged.time, wholes[k].time);
    EXPECT_EQ(merged.step, wholes[k].step);
    for (const auto& field : wholes[k].fields) {
      vtkDataArray* array = grid->GetPointData()->GetArray(field.name.c_str());
      ASSERT_NE(array, nullptr) << field.name;
      for (int i = 0; i < 40; ++i)
        for (int c = 0; c < field.components; ++c)
          ASSERT_EQ(array->GetComponent(at[i], c), field.values[i * field.components + c])
              << field.name;
    }
    for (const auto& flags : wholes[k].flags) {
      auto* array =
          vtkUnsignedCharArray::SafeDownCast(grid->GetPointData()->GetArray(flags.name.c_str()));
      ASSERT_NE(array, nullptr) << flags.name;
      for (int i = 0; i < 40; ++i)
        ASSERT_EQ(array->GetValue(at[i]), flags.values[i]) << flags.name;
    }
  }

  // A piece's ids must match its points.
  Frame bad = pieceOf(wholes[0], owned[0]);
  bad.ids->pop_back();
  EXPECT_THROW(writeVtuFile(bad, dir_ / "bad.vtu"), std::invalid_argument);
}

// A restart keeps the frames up to its checkpoint: the owner of the index files removes the
// later ones, whole frames, indices and piece directories alike; other ranks remove nothing.
TEST_F(OutputTest, ResumeRemovesLaterFramesOfEveryKind) {
  const fs::path series = dir_ / "series";
  std::vector<PvdEntry> firstTwo;
  {
    VtuSeriesWriter writer(series, "beam");
    writer.write(makeFrame(0, 6));
    for (int k = 1; k < 3; ++k) {
      const Frame piece = pieceOf(makeFrame(k, 6), {0, 1, 2, 3, 4, 5});
      writer.writePiece(piece, 0);
      writer.addPieces(piece, 1, true);
      if (k == 1) firstTwo = writer.frames();
    }
    writer.write(makeFrame(3, 6));
    writer.writePiece(pieceOf(makeFrame(4, 6), {0}), 0);  // stopped before its index
  }
  const std::set<std::string> all = {"beam.pvd",         "beam_000000.vtu", "beam_000001",
                                     "beam_000001.pvtu", "beam_000002",     "beam_000002.pvtu",
                                     "beam_000003.vtu",  "beam_000004"};
  ASSERT_EQ(filesIn(series), all);
  VtuSeriesWriter other(series, "beam");
  other.resume(firstTwo, false);
  EXPECT_EQ(filesIn(series), all);
  EXPECT_EQ(other.frameCount(), 2u);
  VtuSeriesWriter owner(series, "beam");
  owner.resume(firstTwo, true);
  EXPECT_EQ(filesIn(series), (std::set<std::string>{"beam.pvd", "beam_000000.vtu", "beam_000001",
                                                    "beam_000001.pvtu"}));
  EXPECT_EQ(readPvd(owner.pvdPath()).size(), 2u);
  EXPECT_EQ(owner.write(makeFrame(2, 6)), series / "beam_000002.vtu");
}

TEST_F(OutputTest, CsvSeriesRoundTripsAndRewrites) {
  const fs::path file = dir_ / "energies.csv";
  const std::vector<std::string> columns = {"time", "kinetic", "strain"};
  CsvSeries csv(file, columns);
  csv.setPreamble({"command: tlsph beam.toml", "units: s, J\nsecond line"});
  const std::vector<std::vector<double>> rows = {
      {0.0, 1.0 / 3.0, -0.0},
      {0.1, 2.2250738585072014e-308, 1.7976931348623157e308},  // std::stod rejects subnormals
      {0.30000000000000004, -2.5e-300, 123456789.123456789},
      {1e-5, std::numeric_limits<double>::infinity(), 2.0 / 3.0}};

  auto readBack = [&] {
    std::ifstream in(file);
    std::vector<std::string> comments;
    std::string header;
    std::vector<std::vector<double>> values;
    for (std::string line; std::getline(in, line);) {
      if (line.rfind("# ", 0) == 0) {
        EXPECT_TRUE(header.empty()) << "comment after the header";
        comments.push_back(line.substr(2));
      } else if (header.empty()) {
        header = line;
      } else {
        std::vector<double> row;
        std::stringstream cells(line);
        for (std::string cell; std::getline(cells, cell, ',');)
          row.push_back(std::stod(cell));
        values.push_back(row);
      }
    }
    EXPECT_EQ(comments,
              (std::vector<std::string>{"command: tlsph beam.toml", "units: s, J", "second line"}));
    EXPECT_EQ(header, "time,kinetic,strain");
    return values;
  };

  csv.append(rows[0]);
  csv.append(rows[1]);
  EXPECT_THROW(csv.append({1.0, 2.0}), std::invalid_argument);
  EXPECT_THROW(csv.append({1.0, 2.0, 3.0, 4.0}), std::invalid_argument);
  EXPECT_EQ(csv.rowCount(), 2u);
  EXPECT_FALSE(fs::exists(file));  // nothing before the first flush
  csv.flush();
  EXPECT_EQ(readBack().size(), 2u);
  const std::string firstFlush = readText(file);
  csv.flush();
  EXPECT_EQ(readText(file), firstFlush);  // rewritten, not appended

  csv.append(rows[2]);
  csv.append(rows[3]);
  csv.flush();
  const auto values = readBack();
  ASSERT_EQ(values.size(), rows.size());
  for (std::size_t r = 0; r < rows.size(); ++r)
    for (std::size_t c = 0; c < columns.size(); ++c) {
      EXPECT_EQ(values[r][c], rows[r][c]) << "row " << r << " column " << c;
      EXPECT_EQ(std::signbit(values[r][c]), std::signbit(rows[r][c]));
    }
  EXPECT_EQ(csv.rowCount(), 4u);
  EXPECT_EQ(filesIn(dir_), std::set<std::string>{"energies.csv"});

  EXPECT_THROW(CsvSeries(file, {}), std::invalid_argument);
  EXPECT_THROW(CsvSeries(file, {"time", "a,b"}), std::invalid_argument);

  // A parent that is a regular file: flush throws naming the file, the target stays absent.
  CsvSeries blocked(file / "probes.csv", columns);
  blocked.append(rows[0]);
  EXPECT_THROW(blocked.flush(), std::runtime_error);
  EXPECT_EQ(readBack().size(), rows.size());
  EXPECT_EQ(filesIn(dir_), std::set<std::string>{"energies.csv"});
}
