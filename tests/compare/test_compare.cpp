// `tlsph compare`: FEM fields interpolated at the particles' reference positions and the error
// norms against them. The FEM meshes here carry linear fields, which their (tri/bi)linear
// elements reproduce exactly, so every expected number is known in closed form.
#include <gtest/gtest.h>
#include <unistd.h>

#include <vtkCellData.h>
#include <vtkCellType.h>
#include <vtkDataArray.h>
#include <vtkDoubleArray.h>
#include <vtkFloatArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkSmartPointer.h>
#include <vtkUnstructuredGrid.h>
#include <vtkUnstructuredGridWriter.h>
#include <vtkXMLUnstructuredGridReader.h>
#include <vtkXMLUnstructuredGridWriter.h>

#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <random>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "ProgramRunner.hpp"
#include "compare/Comparison.hpp"
#include "compare/ComparisonFrame.hpp"
#include "compare/ComparisonReport.hpp"
#include "compare/FieldComparison.hpp"
#include "compare/FieldLayout.hpp"
#include "compare/ParticleFrame.hpp"
#include "compare/RunFrame.hpp"
#include "output/Frame.hpp"
#include "output/VtuFile.hpp"
#include "output/VtuSeriesWriter.hpp"

using namespace tlsph;
namespace fs = std::filesystem;
using tlsph::testing::runProgram;

namespace {

using Point = std::array<double, 3>;
using Tensor = std::array<double, 9>;  // row-major

// ---- linear fields: u = b + A X, sigma = S0 + X S1 + Y S2 + Z S3 (all S symmetric) ----

Point linearDisplacement(const Point& X, int dimension) {
  const double A[3][3] = {{1e-3, 2e-3, -1e-3}, {0.5e-3, -2e-3, 1e-3}, {3e-3, 1e-3, 2e-3}};
  const double b[3] = {1e-4, -2e-4, 3e-4};
  Point u{};
  for (int r = 0; r < dimension; ++r) {
    u[r] = b[r];
    for (int c = 0; c < dimension; ++c)
      u[r] += A[r][c] * X[c];
  }
  return u;
}

Tensor symmetric(double xx, double yy, double zz, double xy, double yz, double xz) {
  return {xx, xy, xz, xy, yy, yz, xz, yz, zz};
}

Tensor linearStress(const Point& X) {
  const Tensor S0 = symmetric(1e5, -2e5, 3e4, 5e4, -1e4, 2e4);
  const Tensor S1 = symmetric(2e5, 1e5, -5e4, 3e4, 2e4, -1e4);
  const Tensor S2 = symmetric(-1e5, 4e4, 2e4, -6e4, 1e4, 3e4);
  const Tensor S3 = symmetric(3e4, -2e4, 1e5, 2e4, -3e4, 5e4);
  Tensor s{};
  for (int k = 0; k < 9; ++k)
    s[k] = S0[k] + X[0] * S1[k] + X[1] * S2[k] + X[2] * S3[k];
  return s;
}

// ---- FEM meshes ----

// Graded node coordinates on [lo, hi]: monotonic, not uniform, so that cells differ.
std::vector<double> gradedNodes(double lo, double hi, int cells) {
  std::vector<double> x(cells + 1);
  for (int i = 0; i <= cells; ++i) {
    const double t = double(i) / cells;
    x[i] = lo + (hi - lo) * (t + 0.08 * std::sin(M_PI * t) * std::cos(M_PI * t));
  }
  x[0] = lo;
  x[cells] = hi;
  return x;
}

// A 3D box of hexahedra (2D: a rectangle of quads at z = 0) on graded nodes.
vtkSmartPointer<vtkUnstructuredGrid> boxMesh(const Point& lo, const Point& hi,
                                             const std::array<int, 3>& cells, int dimension) {
  const auto xs = gradedNodes(lo[0], hi[0], cells[0]);
  const auto ys = gradedNodes(lo[1], hi[1], cells[1]);
  const auto zs = dimension == 3 ? gradedNodes(lo[2], hi[2], cells[2]) : std::vector<double>{0.0};
  const int nx = cells[0] + 1, ny = cells[1] + 1, nz = int(zs.size());
  auto grid = vtkSmartPointer<vtkUnstructuredGrid>::New();
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        points->InsertNextPoint(xs[i], ys[j], zs[k]);
  grid->SetPoints(points);
  auto id = [&](int i, int j, int k) { return vtkIdType(i + nx * (j + ny * k)); };
  for (int k = 0; k < std::max(1, nz - 1); ++k)
    for (int j = 0; j + 1 < ny; ++j)
      for (int i = 0; i + 1 < nx; ++i) {
        if (dimension == 2) {
          const vtkIdType quad[4] = {id(i, j, 0), id(i + 1, j, 0), id(i + 1, j + 1, 0),
                                     id(i, j + 1, 0)};
          grid->InsertNextCell(VTK_QUAD, 4, quad);
        } else {
          const vtkIdType hex[8] = {
              id(i, j, k),     id(i + 1, j, k),     id(i + 1, j + 1, k),     id(i, j + 1, k),
              id(i, j, k + 1), id(i + 1, j, k + 1), id(i + 1, j + 1, k + 1), id(i, j + 1, k + 1)};
          grid->InsertNextCell(VTK_HEXAHEDRON, 8, hex);
        }
      }
  return grid;
}

// Adds a point array of `components` values per node, f(X, out).
void addPointArray(vtkUnstructuredGrid* grid, const std::string& name, int components,
                   const std::function<void(const Point&, double*)>& f) {
  vtkNew<vtkDoubleArray> array;
  array->SetName(name.c_str());
  array->SetNumberOfComponents(components);
  array->SetNumberOfTuples(grid->GetNumberOfPoints());
  for (vtkIdType p = 0; p < grid->GetNumberOfPoints(); ++p) {
    Point X;
    grid->GetPoint(p, X.data());
    f(X, array->GetPointer(p * components));
  }
  grid->GetPointData()->AddArray(array);
}

void addLinearFields(vtkUnstructuredGrid* grid, int dimension,
                     const std::string& uName = "displacement",
                     const std::string& sName = "cauchy_stress", bool voigt = false) {
  addPointArray(grid, uName, 3, [&](const Point& X, double* out) {
    const Point u = linearDisplacement(X, dimension);
    std::copy(u.begin(), u.end(), out);
  });
  addPointArray(grid, sName, voigt ? 6 : 9, [&](const Point& X, double* out) {
    const Tensor s = linearStress(X);
    if (voigt) {
      const double v[6] = {s[0], s[4], s[8], s[1], s[5], s[2]};  // xx yy zz xy yz xz
      std::copy(v, v + 6, out);
    } else {
      std::copy(s.begin(), s.end(), out);
    }
  });
}

void writeGrid(vtkUnstructuredGrid* grid, const fs::path& file) {
  if (file.extension() == ".vtk") {
    vtkNew<vtkUnstructuredGridWriter> writer;
    writer->SetInputData(grid);
    writer->SetFileName(file.c_str());
    writer->SetFileTypeToBinary();
    ASSERT_EQ(writer->Write(), 1) << file;
  } else {
    vtkNew<vtkXMLUnstructuredGridWriter> writer;
    writer->SetInputData(grid);
    writer->SetFileName(file.c_str());
    ASSERT_EQ(writer->Write(), 1) << file;
  }
}

// ---- tlsph frames ----

// Cell-centred lattice particles (i + 1/2) dx filling [0, n dx] per axis (2D: z = 0), plus
// `ghostLayers` layers of ghosts at x < 0 as a clamp would add them.
struct Lattice {
  std::vector<Point> X;
  std::vector<std::uint8_t> ghost;
};

Lattice lattice(const std::array<int, 3>& n, double dx, int dimension, int ghostLayers) {
  Lattice l;
  const int nz = dimension == 3 ? n[2] : 1;
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = -ghostLayers; i < n[0]; ++i) {
        l.X.push_back({(i + 0.5) * dx, (j + 0.5) * dx, dimension == 3 ? (k + 0.5) * dx : 0.0});
        l.ghost.push_back(i < 0);
      }
  return l;
}

using Perturbation = std::function<void(std::size_t, const Point&, double*)>;

// A frame as `tlsph run` writes it: points x = X + u, displacement, cauchy_stress, flags.
// The tlsph values are the linear fields plus the perturbations (if any).
Frame latticeFrame(const Lattice& l, int dimension, const Perturbation& du = {},
                   const Perturbation& dsigma = {}, bool withDisplacement = true) {
  Frame frame;
  frame.time = 0.25;
  frame.step = 1234;
  PointField u{"displacement", 3, {}}, sigma{"cauchy_stress", 9, {}};
  for (std::size_t i = 0; i < l.X.size(); ++i) {
    Point ui = linearDisplacement(l.X[i], dimension);
    if (du) du(i, l.X[i], ui.data());
    Tensor si = linearStress(l.X[i]);
    if (dsigma) dsigma(i, l.X[i], si.data());
    frame.points.push_back({l.X[i][0] + ui[0], l.X[i][1] + ui[1], l.X[i][2] + ui[2]});
    u.values.insert(u.values.end(), ui.begin(), ui.end());
    sigma.values.insert(sigma.values.end(), si.begin(), si.end());
  }
  if (withDisplacement) frame.fields.push_back(u);
  frame.fields.push_back(sigma);
  frame.flags.push_back(PointFlags{"ghost", l.ghost});
  frame.flags.push_back(PointFlags{"body", std::vector<std::uint8_t>(l.X.size(), 0)});
  return frame;
}

std::string readText(const fs::path& file) {
  std::ifstream in(file);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

class CompareTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::random_device seed;
    dir_ = fs::temp_directory_path() /
           ("tlsph_test_compare_" + std::to_string(::getpid()) + "_" + std::to_string(seed()));
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ignored;
    fs::remove_all(dir_, ignored);
  }

  // Writes the FEM mesh and the frame, compares them.
  Comparison run(vtkUnstructuredGrid* fem, const Frame& frame, CompareRequest request = {},
                 const std::string& femName = "fem.vtu") {
    writeGrid(fem, dir_ / femName);
    writeVtuFile(frame, dir_ / "frame.vtu");
    request.run = dir_ / "frame.vtu";
    request.fem = dir_ / femName;
    return compareWithFem(request);
  }

  fs::path dir_;
};

const FieldErrors& errorsOf(const Comparison& c, const std::string& field) {
  for (const auto& f : c.fields)
    if (f.errors.field == field) return f.errors;
  throw std::runtime_error("no field " + field);
}

std::string messageOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "(no exception)";
}

}  // namespace

// ---- the numbers on plain arrays ----

TEST(FieldComparison, NormsOfAHandComputedCase) {
  // e = (3, 4, 0), (0, 0, -1), (0, 0, 0), and a masked-out point with a huge error.
  const std::vector<double> value{3, 4, 0, 0, 0, 0, 1, 0, 0, 1e9, 0, 0};
  const std::vector<double> reference{0, 0, 0, 0, 0, 1, 1, 0, 0, 0, 0, 0};
  const std::vector<std::uint8_t> mask{1, 1, 1, 0};
  const std::vector<Point> at{{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {3, 0, 0}};
  const FieldErrors e = compareField("displacement", 3, value, reference, mask, at);
  EXPECT_EQ(e.compared, 3u);
  EXPECT_DOUBLE_EQ(e.l2Relative, std::sqrt(26.0 / 2.0));
  EXPECT_DOUBLE_EQ(e.rmsAbsolute, std::sqrt(26.0 / 3.0));
  EXPECT_DOUBLE_EQ(e.maxAbsolute, 5.0);
  EXPECT_EQ(e.maxIndex, 0u);
  EXPECT_DOUBLE_EQ(e.maxReference, 1.0);
  EXPECT_DOUBLE_EQ(e.maxRelative, 5.0);

  // A zero reference has no relative error; no compared point gives NaN throughout.
  const FieldErrors zero =
      compareField("displacement", 3, value, std::vector<double>(12, 0.0), mask, at);
  EXPECT_TRUE(std::isnan(zero.l2Relative));
  EXPECT_TRUE(std::isnan(zero.maxRelative));
  EXPECT_DOUBLE_EQ(zero.maxAbsolute, 5.0);
  const FieldErrors none =
      compareField("displacement", 3, value, reference, std::vector<std::uint8_t>(4, 0), at);
  EXPECT_EQ(none.compared, 0u);
  EXPECT_TRUE(std::isnan(none.rmsAbsolute));
  EXPECT_THROW(compareField("displacement", 3, value, reference, {1, 1}, at),
               std::invalid_argument);
}

TEST(FieldLayout, VoigtStressIsExpandedInVtkOrder) {
  const ComparableField& stress = *findComparableField("cauchy_stress");
  const double voigt[6] = {11, 22, 33, 12, 23, 13};  // xx yy zz xy yz xz
  double full[9];
  ASSERT_TRUE(acceptsFemLayout(stress, 6));
  toTlsphLayout(stress, 6, voigt, full);
  const double expected[9] = {11, 12, 13, 12, 22, 23, 13, 23, 33};
  for (int k = 0; k < 9; ++k)
    EXPECT_EQ(full[k], expected[k]) << k;
  EXPECT_FALSE(acceptsFemLayout(stress, 4));
  const ComparableField& u = *findComparableField("displacement");
  const double planar[2] = {1.5, -2.5};
  double u3[3] = {9, 9, 9};
  ASSERT_TRUE(acceptsFemLayout(u, 2));
  toTlsphLayout(u, 2, planar, u3);
  EXPECT_EQ(u3[0], 1.5);
  EXPECT_EQ(u3[1], -2.5);
  EXPECT_EQ(u3[2], 0.0);
  EXPECT_FALSE(acceptsFemLayout(u, 1));
  EXPECT_EQ(findComparableField("von_mises"), nullptr);
}

// ---- (1) the same linear field: zero error ----

TEST_F(CompareTest, SameLinearFieldGivesRoundOffErrors3D) {
  auto fem = boxMesh({0, 0, 0}, {1.0, 0.5, 0.2}, {7, 4, 3}, 3);
  addLinearFields(fem, 3);
  const Lattice l = lattice({20, 10, 4}, 0.05, 3, 2);
  const Comparison c = run(fem, latticeFrame(l, 3));
  EXPECT_EQ(c.ghosts, 2u * 10 * 4);
  EXPECT_EQ(c.bodyParticles(), 20u * 10 * 4);
  EXPECT_EQ(c.insideCount, c.bodyParticles());
  EXPECT_TRUE(c.warnings.empty());
  ASSERT_EQ(c.fields.size(), 2u);  // both files carry the stress: compared by default
  for (const auto& f : c.fields) {
    EXPECT_EQ(f.errors.compared, 800u) << f.errors.field;
    EXPECT_LT(f.errors.l2Relative, 1e-12) << f.errors.field;
    EXPECT_LT(f.errors.maxRelative, 1e-12) << f.errors.field;
    EXPECT_GT(f.errors.maxReference, 0.0) << f.errors.field;
  }
  EXPECT_EQ(c.time, 0.25);
  EXPECT_EQ(c.step, 1234);
  // Reference positions are X = x - u, not the deformed points.
  EXPECT_NEAR(c.reference[0][0], 0.025, 1e-15);
  EXPECT_NEAR(c.reference[0][1], 0.025, 1e-15);
}

TEST_F(CompareTest, SameLinearFieldGivesRoundOffErrors2D) {
  auto fem = boxMesh({0, 0, 0}, {0.4, 0.1, 0}, {9, 3, 0}, 2);
  addLinearFields(fem, 2);
  const Lattice l = lattice({40, 10, 1}, 0.01, 2, 3);
  const Comparison c = run(fem, latticeFrame(l, 2));
  EXPECT_EQ(c.insideCount, 400u);
  EXPECT_EQ(c.ghosts, 30u);
  for (const auto& f : c.fields) {
    EXPECT_LT(f.errors.l2Relative, 1e-12) << f.errors.field;
    EXPECT_LT(f.errors.maxRelative, 1e-12) << f.errors.field;
  }
}

// ---- (2) a known perturbation: the reported norms are its norms ----

void expectKnownErrors(const Comparison& c, const Lattice& l, int dimension,
                       const Perturbation& du) {
  // The expected numbers straight from their definitions over the body particles.
  double e2 = 0, r2 = 0, max2 = -1, maxRef2 = 0;
  std::size_t n = 0, at = 0;
  for (std::size_t i = 0; i < l.X.size(); ++i) {
    if (l.ghost[i]) continue;
    Point d{};
    du(i, l.X[i], d.data());
    const Point u = linearDisplacement(l.X[i], dimension);
    const double di2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    e2 += di2;
    r2 += u[0] * u[0] + u[1] * u[1] + u[2] * u[2];
    maxRef2 = std::max(maxRef2, u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    if (di2 > max2) {
      max2 = di2;
      at = i;
    }
    ++n;
  }
  const FieldErrors& e = errorsOf(c, "displacement");
  EXPECT_EQ(e.compared, n);
  EXPECT_NEAR(e.l2Relative, std::sqrt(e2 / r2), 1e-10 * std::sqrt(e2 / r2));
  EXPECT_NEAR(e.rmsAbsolute, std::sqrt(e2 / n), 1e-10 * std::sqrt(e2 / n));
  EXPECT_NEAR(e.maxAbsolute, std::sqrt(max2), 1e-10 * std::sqrt(max2));
  EXPECT_NEAR(e.maxReference, std::sqrt(maxRef2), 1e-12 * std::sqrt(maxRef2));
  EXPECT_NEAR(e.maxRelative, std::sqrt(max2 / maxRef2), 1e-10 * std::sqrt(max2 / maxRef2));
  EXPECT_EQ(c.frameIndex[e.maxIndex], at);
  for (int a = 0; a < 3; ++a)
    EXPECT_NEAR(e.maxAt[a], l.X[at][a], 1e-14) << a;
}

TEST_F(CompareTest, KnownPerturbationGivesItsNorms3D) {
  auto fem = boxMesh({0, 0, 0}, {1.0, 0.5, 0.2}, {7, 4, 3}, 3);
  addLinearFields(fem, 3);
  const Lattice l = lattice({20, 10, 4}, 0.05, 3, 2);
  const Perturbation du = [](std::size_t, const Point& X, double* u) {
    const double d[3] = {2e-5 * std::sin(7 * X[0]), -3e-5 * std::cos(5 * X[1]) * X[0],
                         1e-5 * std::sin(3 * X[2] + X[0])};
    for (int a = 0; a < 3; ++a)
      u[a] += d[a];
  };
  // And the stress off by a constant 1 kPa in sigma_xx everywhere.
  const Perturbation ds = [](std::size_t, const Point&, double* s) { s[0] += 1e3; };
  const Comparison c = run(fem, latticeFrame(l, 3, du, ds));
  expectKnownErrors(c, l, 3, [&](std::size_t i, const Point& X, double* d) {
    d[0] = d[1] = d[2] = 0.0;
    du(i, X, d);
  });
  const FieldErrors& s = errorsOf(c, "cauchy_stress");
  EXPECT_NEAR(s.rmsAbsolute, 1e3, 1e-7);
  EXPECT_NEAR(s.maxAbsolute, 1e3, 1e-7);
}

TEST_F(CompareTest, KnownPerturbationGivesItsNorms2D) {
  auto fem = boxMesh({0, 0, 0}, {0.4, 0.1, 0}, {9, 3, 0}, 2);
  addLinearFields(fem, 2);
  const Lattice l = lattice({40, 10, 1}, 0.01, 2, 3);
  // One particle far off, the rest slightly.
  const Perturbation du = [](std::size_t i, const Point& X, double* u) {
    u[0] += (i == 123 ? 4e-4 : 1e-6 * std::cos(40 * X[0]));
    u[1] += -2e-6 * X[1];
  };
  const Comparison c = run(fem, latticeFrame(l, 2, du));
  expectKnownErrors(c, l, 2, [&](std::size_t i, const Point& X, double* d) {
    d[0] = d[1] = d[2] = 0.0;
    du(i, X, d);
  });
  EXPECT_EQ(c.frameIndex[errorsOf(c, "displacement").maxIndex], 123u);
}

// ---- (3) particles outside the FEM mesh ----

TEST_F(CompareTest, ParticlesOutsideTheMeshAreSkippedAndCounted) {
  // The mesh covers x <= 0.6 of a body that spans x <= 1: particles with X > 0.6 are outside.
  auto fem = boxMesh({0, 0, 0}, {0.6, 0.5, 0.2}, {5, 4, 3}, 3);
  addLinearFields(fem, 3);
  const Lattice l = lattice({20, 10, 4}, 0.05, 3, 2);
  std::size_t outside = 0;
  for (std::size_t i = 0; i < l.X.size(); ++i)
    outside += !l.ghost[i] && l.X[i][0] > 0.6;
  ASSERT_EQ(outside, 8u * 10 * 4);
  const Comparison c = run(fem, latticeFrame(l, 3));
  EXPECT_EQ(c.bodyParticles() - c.insideCount, outside);
  EXPECT_EQ(errorsOf(c, "displacement").compared, c.bodyParticles() - outside);
  EXPECT_LT(errorsOf(c, "displacement").l2Relative, 1e-12);
  ASSERT_EQ(c.warnings.size(), 1u);  // 40 % outside: warned
  EXPECT_NE(c.warnings[0].find("320 of 800 particles"), std::string::npos) << c.warnings[0];

  // In the error file: compared = 0 there, and NaN rather than a made-up zero.
  const Frame out = comparisonFrame(c);
  ASSERT_EQ(out.points.size(), 800u);
  const auto& compared = out.flags.at(0);
  ASSERT_EQ(compared.name, "compared");
  for (std::size_t i = 0; i < out.points.size(); ++i) {
    EXPECT_EQ(compared.values[i], out.points[i][0] > 0.6 ? 0 : 1) << i;
    const auto& fem0 = out.fields.at(0);
    ASSERT_EQ(fem0.name, "fem_displacement");
    EXPECT_EQ(std::isnan(fem0.values[3 * i]), out.points[i][0] > 0.6) << i;
  }

  // Nobody inside: an error that gives both extents.
  auto far = boxMesh({5, 5, 5}, {6, 6, 6}, {2, 2, 2}, 3);
  addLinearFields(far, 3);
  const std::string message = messageOf([&] { run(far, latticeFrame(l, 3)); });
  EXPECT_NE(message.find("none of the 800 particles"), std::string::npos) << message;
  EXPECT_NE(message.find("mesh bounds [5, 6]"), std::string::npos) << message;
}

TEST_F(CompareTest, ParticlesOnTheMeshBoundaryAreFound) {
  // Mesh nodes exactly at the outermost particles: X = x - u is only round-off close to them.
  const double dx = 0.05;
  auto fem =
      boxMesh({dx / 2, dx / 2, dx / 2}, {1 - dx / 2, 0.5 - dx / 2, 0.2 - dx / 2}, {19, 9, 3}, 3);
  addLinearFields(fem, 3);
  const Lattice l = lattice({20, 10, 4}, dx, 3, 0);
  const Comparison c = run(fem, latticeFrame(l, 3));
  EXPECT_EQ(c.insideCount, 800u);
  EXPECT_LT(errorsOf(c, "displacement").maxRelative, 1e-12);
}

// ---- (4) FEM layouts: Voigt stress, cell data, legacy files, named arrays ----

TEST_F(CompareTest, VoigtStressFromALegacyFileIsExpanded) {
  auto fem = boxMesh({0, 0, 0}, {1.0, 0.5, 0.2}, {7, 4, 3}, 3);
  addLinearFields(fem, 3, "U", "S", /*voigt=*/true);
  const Lattice l = lattice({20, 10, 4}, 0.05, 3, 2);
  CompareRequest request;
  request.femArrays = {{"displacement", "U"}, {"cauchy_stress", "S"}};
  const Comparison c = run(fem, latticeFrame(l, 3), request, "fem.vtk");
  const FieldErrors& s = errorsOf(c, "cauchy_stress");
  EXPECT_EQ(s.compared, 800u);
  EXPECT_LT(s.maxRelative, 1e-12);  // a wrong Voigt order would be off by ~1e5 Pa
  EXPECT_LT(errorsOf(c, "displacement").maxRelative, 1e-12);
  bool noted = false;
  for (const auto& note : c.notes)
    noted = noted || note.find("6 symmetric components") != std::string::npos;
  EXPECT_TRUE(noted);
}

TEST_F(CompareTest, CellDataIsConstantPerElement) {
  auto fem = boxMesh({0, 0, 0}, {1.0, 0.5, 0.2}, {7, 4, 3}, 3);
  addLinearFields(fem, 3, "displacement", "unused");
  vtkNew<vtkFloatArray> stress;  // Float32 as many FEM writers store it
  stress->SetName("cauchy_stress");
  stress->SetNumberOfComponents(9);
  const Tensor s0 = symmetric(1e5, -2e5, 3e4, 5e4, -1e4, 2e4);
  for (vtkIdType cell = 0; cell < fem->GetNumberOfCells(); ++cell) {
    float v[9];
    for (int k = 0; k < 9; ++k)
      v[k] = float(s0[k]);
    stress->InsertNextTypedTuple(v);
  }
  fem->GetCellData()->AddArray(stress);
  const Lattice l = lattice({20, 10, 4}, 0.05, 3, 0);
  CompareRequest request;
  request.fields = {"cauchy_stress"};
  const Comparison c = run(fem,
                           latticeFrame(l, 3, {},
                                        [&](std::size_t, const Point&, double* s) {
                                          std::copy(s0.begin(), s0.end(), s);
                                        }),
                           request);
  ASSERT_EQ(c.fields.size(), 1u);
  EXPECT_EQ(c.fields[0].errors.compared, 800u);
  EXPECT_EQ(c.fields[0].errors.maxAbsolute, 0.0);
}

// ---- (5) bad input names the file, the field and what was expected ----

TEST_F(CompareTest, MissingDisplacementNamesTheFrame) {
  auto fem = boxMesh({0, 0, 0}, {1.0, 0.5, 0.2}, {7, 4, 3}, 3);
  addLinearFields(fem, 3);
  const Lattice l = lattice({20, 10, 4}, 0.05, 3, 0);
  const std::string message =
      messageOf([&] { run(fem, latticeFrame(l, 3, {}, {}, /*withDisplacement=*/false)); });
  EXPECT_NE(message.find((dir_ / "frame.vtu").string()), std::string::npos) << message;
  EXPECT_NE(message.find("'displacement'"), std::string::npos) << message;
  EXPECT_NE(message.find("[output] fields"), std::string::npos) << message;
}

TEST_F(CompareTest, BadFemArraysAreNamed) {
  const Lattice l = lattice({20, 10, 4}, 0.05, 3, 0);
  auto fem = boxMesh({0, 0, 0}, {1.0, 0.5, 0.2}, {7, 4, 3}, 3);
  addLinearFields(fem, 3, "U", "S");
  // The default names are not there: the message lists what is.
  std::string message = messageOf([&] { run(fem, latticeFrame(l, 3)); });
  EXPECT_NE(message.find((dir_ / "fem.vtu").string()), std::string::npos) << message;
  EXPECT_NE(message.find("no point or cell array 'displacement'"), std::string::npos) << message;
  EXPECT_NE(message.find("its arrays: U, S"), std::string::npos) << message;
  EXPECT_NE(message.find("--fem-fields displacement=NAME"), std::string::npos) << message;

  // A stress with 4 components.
  auto four = boxMesh({0, 0, 0}, {1.0, 0.5, 0.2}, {7, 4, 3}, 3);
  addLinearFields(four, 3, "displacement", "unused");
  addPointArray(four, "cauchy_stress", 4,
                [](const Point&, double* s) { s[0] = s[1] = s[2] = s[3] = 0; });
  message = messageOf([&] { run(four, latticeFrame(l, 3)); });
  EXPECT_NE(message.find("array 'cauchy_stress' has 4 components, expected 9"), std::string::npos)
      << message;

  // Asked for a field the frame lacks; an unknown field; an unreadable file.
  Frame noStress = latticeFrame(l, 3);
  noStress.fields.pop_back();
  CompareRequest request;
  request.fields = {"displacement", "cauchy_stress"};
  message = messageOf([&] { run(fem, noStress, request); });
  EXPECT_NE(message.find("has no point field 'cauchy_stress'"), std::string::npos) << message;
  request.fields = {"von_mises"};
  message = messageOf([&] { run(fem, noStress, request); });
  EXPECT_NE(message.find("'von_mises' is not a field compare knows"), std::string::npos) << message;
  std::ofstream(dir_ / "garbage.vtu") << "not VTK\n";
  request = {};
  request.run = dir_ / "frame.vtu";
  request.fem = dir_ / "garbage.vtu";
  message = messageOf([&] { compareWithFem(request); });
  EXPECT_NE(message.find("cannot read FEM file " + (dir_ / "garbage.vtu").string()),
            std::string::npos)
      << message;
}

// ---- RUN: a directory, a .pvd or a .vtu; --frame ----

TEST_F(CompareTest, FramesAreFoundFromTheRunDirectory) {
  const Lattice l = lattice({4, 2, 2}, 0.05, 3, 0);
  VtuSeriesWriter series(dir_ / "run", "beam");
  for (int k = 0; k < 3; ++k) {
    Frame frame = latticeFrame(l, 3);
    frame.time = 0.5 * k;
    series.write(frame);
  }
  // Without summary.json: the directory's only .pvd.
  FrameChoice choice = chooseFrame(dir_ / "run", "");
  EXPECT_EQ(choice.file, dir_ / "run" / "beam_000002.vtu");
  EXPECT_EQ(choice.count, 3u);
  EXPECT_EQ(choice.time, 1.0);
  choice = chooseFrame(dir_ / "run" / "beam.pvd", "1");
  EXPECT_EQ(choice.file, dir_ / "run" / "beam_000001.vtu");
  EXPECT_EQ(choice.index, 1u);
  // With one: its "pvd", by file name (the recorded path is relative to where the run started).
  fs::copy_file(dir_ / "run" / "beam.pvd", dir_ / "run" / "other.pvd");
  std::ofstream(dir_ / "run" / "summary.json") << "{\n  \"pvd\": \"somewhere/else/beam.pvd\",\n"
                                                  "  \"probes\": \"\"\n}\n";
  EXPECT_EQ(chooseFrame(dir_ / "run", "last").file, dir_ / "run" / "beam_000002.vtu");
  EXPECT_NE(messageOf([&] { chooseFrame(dir_ / "run", "3"); }).find("has 3 frames, numbered 0..2"),
            std::string::npos);
  EXPECT_NE(messageOf([&] { chooseFrame(dir_ / "run", "-1"); }).find("expected 'last' or"),
            std::string::npos);
  EXPECT_NE(messageOf([&] {
              chooseFrame(dir_ / "run" / "beam_000001.vtu", "0");
            }).find("is a single frame"),
            std::string::npos);
  EXPECT_NE(messageOf([&] { chooseFrame(dir_ / "nothing", ""); }).find("does not exist"),
            std::string::npos);
  fs::remove(dir_ / "run" / "summary.json");
  EXPECT_NE(messageOf([&] { chooseFrame(dir_ / "run", ""); }).find("several .pvd series"),
            std::string::npos);
}

// A distributed run's frame (a .pvtu of per-rank pieces) is found in its run directory and
// compares as the whole frame: the same particles, ghosts, time and norms.
TEST_F(CompareTest, FramesInPiecesCompareAsTheWholeFrame) {
  auto fem = boxMesh({0, 0, 0}, {1.0, 0.5, 0.2}, {7, 4, 3}, 3);
  addLinearFields(fem, 3);
  const Lattice l = lattice({20, 10, 4}, 0.05, 3, 2);
  const Perturbation du = [](std::size_t, const Point& X, double* u) {
    u[0] += 2e-5 * std::sin(7 * X[0]);
    u[2] += 1e-5 * std::cos(3 * X[1]);
  };
  const Frame whole = latticeFrame(l, 3, du);
  const Comparison expected = run(fem, whole);

  // Two ranks: the particles split in alternate blocks of 50.
  VtuSeriesWriter series(dir_ / "run", "beam");
  std::vector<Frame> pieces(2);
  for (int r = 0; r < 2; ++r) {
    Frame& piece = pieces[r];
    piece.time = whole.time;
    piece.step = whole.step;
    piece.ids.emplace();
    piece.fields = {{"displacement", 3, {}}, {"cauchy_stress", 9, {}}};
    piece.flags = {{"ghost", {}}, {"body", {}}};
    for (std::size_t i = 0; i < whole.points.size(); ++i) {
      if (int(i / 50 % 2) != r) continue;
      piece.ids->push_back(std::int64_t(i));
      piece.points.push_back(whole.points[i]);
      for (std::size_t f = 0; f < 2; ++f) {
        const int c = whole.fields[f].components;
        const auto at = whole.fields[f].values.begin() + std::ptrdiff_t(c * i);
        piece.fields[f].values.insert(piece.fields[f].values.end(), at, at + c);
        piece.flags[f].values.push_back(whole.flags[f].values[i]);
      }
    }
    series.writePiece(piece, r);
  }
  series.addPieces(pieces[0], 2, true);
  const FrameChoice choice = chooseFrame(dir_ / "run", "");
  EXPECT_EQ(choice.file, dir_ / "run" / "beam_000000.pvtu");
  EXPECT_EQ(chooseFrame(choice.file, "").file, choice.file);  // a lone .pvtu frame
  const ParticleFrame read = readParticleFrame(choice.file);
  EXPECT_EQ(read.size(), whole.points.size());
  EXPECT_EQ(read.time, whole.time);
  EXPECT_EQ(read.step, whole.step);
  ASSERT_NE(read.field("id"), nullptr);

  CompareRequest request;
  request.run = dir_ / "run";
  request.fem = dir_ / "fem.vtu";
  const Comparison c = compareWithFem(request);
  EXPECT_EQ(c.ghosts, expected.ghosts);
  EXPECT_EQ(c.bodyParticles(), expected.bodyParticles());
  EXPECT_EQ(c.insideCount, expected.insideCount);
  ASSERT_EQ(c.fields.size(), expected.fields.size());
  for (std::size_t f = 0; f < c.fields.size(); ++f) {
    const FieldErrors &a = c.fields[f].errors, &b = expected.fields[f].errors;
    EXPECT_EQ(a.compared, b.compared) << a.field;
    EXPECT_NEAR(a.l2Relative, b.l2Relative, 1e-12 * b.l2Relative) << a.field;  // summed in
    EXPECT_EQ(a.maxAbsolute, b.maxAbsolute) << a.field;                        // another order
  }
  EXPECT_GT(errorsOf(c, "displacement").maxAbsolute, 1e-6);
}

// ---- (6) end to end: `tlsph run`, then `tlsph compare` against an FEM-like mesh ----

namespace {

// The number after "key": inside the JSON object of `field`.
double jsonValue(const std::string& json, const std::string& field, const std::string& key) {
  const auto start = json.find("\"" + field + "\": {");
  const auto end = json.find('}', start);
  std::smatch m;
  const std::string block = json.substr(start, end - start);
  if (start == std::string::npos ||
      !std::regex_search(block, m, std::regex("\"" + key + "\": ([-0-9.eE+]+)")))
    return std::nan("");
  return std::stod(m[1]);
}

}  // namespace

TEST_F(CompareTest, EndToEndAgainstTheRunAsAnFemMesh) {
  // The clamped plate (40 x 40 x 4 particles, dx = 12.5 mm), static.
  const fs::path out = dir_ / "plate";
  tlsph::testing::ProgramResult r =
      runProgram("run " + std::string(TLSPH_SOURCE_DIR) +
                     "/examples/clamped_plate.ini --output.directory=" + out.string() +
                     " \"--output.fields=displacement cauchy_stress flags\"",
                 dir_ / "run.log");
  ASSERT_EQ(r.status, 0) << r.output;

  // An "FEM" hexahedral mesh whose nodes are the body particles' reference positions, carrying
  // the run's own displacement shifted by a constant c (array U) and its stress in Voigt form
  // (array S): the comparison must find every particle (the outermost ones lie on the mesh
  // boundary), e = -c exactly, and the stress equal.
  const ParticleFrame frame = readParticleFrame(chooseFrame(out, "").file);
  const PointField& u = *frame.field("displacement");
  const PointField& sigma = *frame.field("cauchy_stress");
  const double dx = 0.0125;
  const Point c{3e-5, -4e-5, 1.2e-4};  // |c| = 1.3e-4 m
  std::map<std::array<int, 3>, vtkIdType> node;
  auto grid = vtkSmartPointer<vtkUnstructuredGrid>::New();
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  vtkNew<vtkDoubleArray> U, S;
  U->SetName("U");
  U->SetNumberOfComponents(3);
  S->SetName("S");
  S->SetNumberOfComponents(6);
  std::size_t body = 0;
  for (std::size_t i = 0; i < frame.size(); ++i) {
    if (frame.ghost[i]) continue;
    ++body;
    const Point& X = frame.reference[i];
    const std::array<int, 3> ijk{int(std::lround(X[0] / dx - 0.5)),
                                 int(std::lround(X[1] / dx - 0.5)),
                                 int(std::lround(X[2] / dx - 0.5))};
    // The node at the exact lattice position; X itself differs from it by round-off.
    node[ijk] =
        points->InsertNextPoint((ijk[0] + 0.5) * dx, (ijk[1] + 0.5) * dx, (ijk[2] + 0.5) * dx);
    const double ui[3] = {u.values[3 * i] + c[0], u.values[3 * i + 1] + c[1],
                          u.values[3 * i + 2] + c[2]};
    U->InsertNextTuple(ui);
    const double* s = &sigma.values[9 * i];
    const double voigt[6] = {s[0], s[4], s[8], s[1], s[5], s[2]};
    S->InsertNextTuple(voigt);
  }
  ASSERT_EQ(body, 40u * 40 * 4);
  grid->SetPoints(points);
  grid->GetPointData()->AddArray(U);
  grid->GetPointData()->AddArray(S);
  for (int k = 0; k + 1 < 4; ++k)
    for (int j = 0; j + 1 < 40; ++j)
      for (int i = 0; i + 1 < 40; ++i) {
        vtkIdType hex[8];
        const int corner[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                                  {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
        for (int v = 0; v < 8; ++v)
          hex[v] = node.at({i + corner[v][0], j + corner[v][1], k + corner[v][2]});
        grid->InsertNextCell(VTK_HEXAHEDRON, 8, hex);
      }
  writeGrid(grid, dir_ / "plate_fem.vtu");

  r = runProgram("compare " + out.string() + " " + (dir_ / "plate_fem.vtu").string() +
                     " --fem-fields displacement=U,cauchy_stress=S --output " +
                     (dir_ / "errors.vtu").string() + " --json " + (dir_ / "errors.json").string(),
                 dir_ / "compare.log");
  ASSERT_EQ(r.status, 0) << r.output;
  std::cout << r.output;
  EXPECT_NE(r.output.find("6400 body particles (1920 ghosts left out): 6400 inside the FEM mesh"),
            std::string::npos)
      << r.output;
  EXPECT_EQ(r.output.find("warning"), std::string::npos) << r.output;

  const double cNorm = std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
  const std::string json = readText(dir_ / "errors.json");
  EXPECT_NEAR(jsonValue(json, "displacement", "compared"), 6400, 0) << json;
  EXPECT_NEAR(jsonValue(json, "displacement", "max_absolute"), cNorm, 1e-9 * cNorm) << json;
  EXPECT_NEAR(jsonValue(json, "displacement", "rms_absolute"), cNorm, 1e-9 * cNorm) << json;
  const double maxU = jsonValue(json, "displacement", "max_reference");
  EXPECT_GT(maxU, 3e-4);  // the plate's centre deflection is about 0.7 mm
  EXPECT_LT(maxU, 2e-3);
  EXPECT_LT(jsonValue(json, "cauchy_stress", "l2_relative"), 1e-12) << json;
  EXPECT_NE(json.find("\"compared_particles\": 6400"), std::string::npos) << json;

  // The error file, read back by VTK.
  vtkNew<vtkXMLUnstructuredGridReader> reader;
  reader->SetFileName((dir_ / "errors.vtu").c_str());
  reader->Update();
  vtkUnstructuredGrid* errors = reader->GetOutput();
  ASSERT_EQ(errors->GetNumberOfPoints(), 6400);
  for (const char* name :
       {"fem_displacement", "tlsph_displacement", "error_displacement",
        "error_displacement_magnitude", "fem_cauchy_stress", "tlsph_cauchy_stress",
        "error_cauchy_stress", "error_cauchy_stress_magnitude", "compared"})
    EXPECT_NE(errors->GetPointData()->GetArray(name), nullptr) << name;
  vtkDataArray* magnitude = errors->GetPointData()->GetArray("error_displacement_magnitude");
  vtkDataArray* error = errors->GetPointData()->GetArray("error_displacement");
  vtkDataArray* compared = errors->GetPointData()->GetArray("compared");
  ASSERT_TRUE(magnitude && error && compared);
  for (vtkIdType i = 0; i < 6400; i += 97) {
    EXPECT_NEAR(magnitude->GetComponent(i, 0), cNorm, 1e-9 * cNorm) << i;
    EXPECT_NEAR(error->GetComponent(i, 2), -c[2], 1e-9 * cNorm) << i;  // tlsph - fem
    EXPECT_EQ(compared->GetComponent(i, 0), 1.0) << i;
    double X[3];
    errors->GetPoint(i, X);  // reference positions: on the lattice
    for (int a = 0; a < 3; ++a)
      EXPECT_NEAR(std::fmod(X[a] / dx, 1.0), 0.5, 1e-9) << i;
  }

  // Bad input through the program: exit status 1, the file named, nothing written.
  r = runProgram("compare " + out.string() + " " + (dir_ / "plate_fem.vtu").string() +
                     " --output " + (dir_ / "bad.vtu").string() + " --json " +
                     (dir_ / "bad.json").string(),
                 dir_ / "bad.log");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.output.find("plate_fem.vtu has no point or cell array 'displacement'"),
            std::string::npos)
      << r.output;
  EXPECT_FALSE(fs::exists(dir_ / "bad.vtu"));
  EXPECT_FALSE(fs::exists(dir_ / "bad.json"));
}
