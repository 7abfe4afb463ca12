// Bodies read from files: a particle set (CSV, VTU) is taken as it is, and one equal to a
// lattice body's particles gives that body's run bit for bit; a body meshed by gmsh carries
// its named surfaces, which clamps hold and loads act on over their true area.
#include <gtest/gtest.h>
#include <unistd.h>

#include <vtkDoubleArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLUnstructuredGridWriter.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <numbers>
#include <string>

#include "explicit/Solver.hpp"
#include "scene/Config.hpp"
#include "scene/InputError.hpp"
#include "scene/ParticleSetChecks.hpp"
#include "scene/SceneBuilder.hpp"

using namespace tlsph;
namespace fs = std::filesystem;

namespace {

// A folder of its own for each test's files, removed afterwards.
struct ScratchFolder {
  fs::path path;
  ScratchFolder() {
    path = fs::temp_directory_path() /
           ("tlsph-free-form-" + std::to_string(::getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~ScratchFolder() { fs::remove_all(path); }
};

const std::string kMaterial = R"(
[material.rubber]
model = neo-hookean
density = 1000
youngs_modulus = 1e6
poisson_ratio = 0.3
)";

std::string sceneHead(int d, double dx) {
  std::ostringstream s;
  s << "[scene]\ndimension = " << d << "\ndx = " << dx << "\n[time]\nend = 1\n" << kMaterial;
  return s.str();
}

// A free body that moves and deforms: gravity and a spin, no clamp.
const std::string kDrive = R"(
[gravity]
acceleration = 0 -9.81 0
[initial.spin]
profile = rotation
axis = 0 0 1
point = 0 0 0
rate = 3
)";

template <int D>
std::string drive() {
  if constexpr (D == 2)
    return "[gravity]\nacceleration = 0 -9.81\n[initial.spin]\nprofile = "
           "rotation\npoint = 0 0\nrate = 3\n";
  return kDrive;
}

template <int D>
SceneSetup<D> build(const std::string& text, const fs::path& scene) {
  return buildScene<D>(Config::parse(text, scene.string()));
}

template <int D>
void writeCsv(const fs::path& file, const ParticleSet<D>& p) {
  std::ofstream out(file);
  out << "# particles of a lattice box\n" << (D == 2 ? "volume, x, y\n" : "x, y, z, volume\n");
  out << std::setprecision(17);
  for (Index i = 0; i < p.size(); ++i) {
    const auto& X = p.referencePosition[i];
    if constexpr (D == 2)
      out << p.volume[i] << ", " << X[0] << ", " << X[1] << "\n";
    else
      out << X[0] << ", " << X[1] << ", " << X[2] << ", " << p.volume[i] << "\n";
  }
}

template <int D>
void writeVtu(const fs::path& file, const ParticleSet<D>& p) {
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  vtkNew<vtkDoubleArray> volume;
  volume->SetName("volume");
  for (Index i = 0; i < p.size(); ++i) {
    const auto& X = p.referencePosition[i];
    points->InsertNextPoint(X[0], X[1], D == 3 ? X[D - 1] : 0.0);
    volume->InsertNextValue(p.volume[i]);
  }
  vtkNew<vtkUnstructuredGrid> grid;
  grid->SetPoints(points);
  grid->GetPointData()->AddArray(volume);
  vtkNew<vtkXMLUnstructuredGridWriter> writer;
  writer->SetFileName(file.c_str());
  writer->SetInputData(grid);
  ASSERT_EQ(writer->Write(), 1);
}

// The box's own run and the run of its particles read back from a file, step by step.
template <int D>
void expectSameRun(const std::string& extension) {
  ScratchFolder dir;
  const std::string box = D == 2 ? "[body.block]\nshape = box\nlower = 0 0\nupper = 0.1 0.04\n"
                                 : "[body.block]\nshape = box\nlower = 0 0 0\nupper = 0.1 0.04 "
                                   "0.03\n";
  const double dx = 0.01;
  SceneSetup<D> lattice = build<D>(sceneHead(D, dx) + box + drive<D>(), dir.path / "box.ini");
  const fs::path file = dir.path / ("block" + extension);
  if (extension == ".csv")
    writeCsv<D>(file, lattice.scene.particles);
  else
    writeVtu<D>(file, lattice.scene.particles);
  SceneSetup<D> read = build<D>(sceneHead(D, dx) + "[body.block]\nshape = particles\nfile = block" +
                                    extension + "\n" + drive<D>(),
                                dir.path / "read.ini");
  ASSERT_TRUE(read.freeForm);
  ASSERT_EQ(read.scene.particles.size(), lattice.scene.particles.size());
  for (Index i = 0; i < read.scene.particles.size(); ++i) {
    ASSERT_EQ(read.scene.particles.referencePosition[i],
              lattice.scene.particles.referencePosition[i]);
    ASSERT_EQ(read.scene.particles.velocity[i], lattice.scene.particles.velocity[i]);
  }
  Solver<D> a(lattice.scene, lattice.solver), b(read.scene, read.solver);
  EXPECT_EQ(a.timeStep(), b.timeStep());
  for (int k = 0; k < 40; ++k) {
    a.step();
    b.step();
  }
  double moved = 0.0;
  for (Index i = 0; i < read.scene.particles.size(); ++i) {
    ASSERT_EQ(read.scene.particles.displacement[i], lattice.scene.particles.displacement[i]) << i;
    moved = std::max(moved, lattice.scene.particles.displacement[i].norm());
  }
  EXPECT_GT(moved, 1e-4);  // the runs did move the body
}

}  // namespace

TEST(ParticleFile, CsvOfALatticeBoxRunsAsTheBoxBitForBit2D) {
  expectSameRun<2>(".csv");
}
TEST(ParticleFile, CsvOfALatticeBoxRunsAsTheBoxBitForBit3D) {
  expectSameRun<3>(".csv");
}
TEST(ParticleFile, VtuOfALatticeBoxRunsAsTheBoxBitForBit2D) {
  expectSameRun<2>(".vtu");
}
TEST(ParticleFile, VtuOfALatticeBoxRunsAsTheBoxBitForBit3D) {
  expectSameRun<3>(".vtu");
}

TEST(ParticleFile, ErrorsNameTheFileTheLineAndTheProblem) {
  ScratchFolder dir;
  auto message = [&](const std::string& csv, const std::string& extra = "") {
    std::ofstream(dir.path / "set.csv") << csv;
    try {
      build<2>(sceneHead(2, 0.01) + "[body.b]\nshape = particles\nfile = set.csv\n" + extra,
               dir.path / "s.ini");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(message("x, y\n0 ,0\n").find("set.csv:1: the header has no column 'volume'"),
            std::string::npos)
      << message("x, y\n0 ,0\n");
  EXPECT_NE(message("x,y,volume\n0,0,1e-4\n1,2\n")
                .find("set.csv:3: 2 values, but the header "
                      "names 3 columns"),
            std::string::npos);
  EXPECT_NE(message("x,y,volume\n0,0,-1e-4\n").find("set.csv:2: volume = -1e-4"),
            std::string::npos);
  EXPECT_NE(message("x,y,volume\n0,0,1e-4\n0,nan,1e-4\n").find("y = 'nan' is not a finite"),
            std::string::npos);
  EXPECT_NE(message("x,y,volume\n0,0,1e-4\n0.5,0,1e-4\n0,0,1e-4\n")
                .find("line 4 repeats the position of line 2"),
            std::string::npos);
  EXPECT_NE(message("x,y,volume\n").find("holds no particle"), std::string::npos);
  // The message starts at the scene's key.
  EXPECT_NE(message("x,y,volume\n").find("s.ini:"), std::string::npos);
  EXPECT_NE(message("x,y,volume\n").find("[body.b] file: "), std::string::npos);
  // A particle body is the scene's only body, without holes.
  EXPECT_NE(message("x,y,volume\n0,0,1e-4\n", "[body.c]\nshape = box\nlower = 0 0\nupper = 1 1\n")
                .find("must be the scene's only body"),
            std::string::npos);
  EXPECT_NE(message("x,y,volume\n0,0,1e-4\n", "[hole.h]\nshape = ball\ncentre = 0 0\nradius = 1\n")
                .find("cut the hole in the CAD model"),
            std::string::npos);
  // A particle file's face is mirrored (odd reflection) or held; the quadratic extrapolation
  // needs the lattice's layers.
  EXPECT_NE(message("x,y,volume\n0,0,1e-4\n1,0,1e-4\n",
                    "[clamp.c]\nface = x-\nmethod = mirror-quadratic\n")
                .find("method = mirror"),
            std::string::npos);
  // The mirror's plane must leave every particle on the body's side.
  EXPECT_NE(
      message("x,y,volume\n0,0,1e-4\n1,0,1e-4\n", "[clamp.c]\nface = x-\nat = 0.5\n")
          .find("[clamp.c] at: particle 0 at (0 0) lies on or beyond the clamp's plane x = 0.5"),
      std::string::npos);
  // Particles on top of each other, and two clouds over the same space, are refused by name.
  EXPECT_NE(
      message("x,y,volume\n0,0,1e-4\n0.01,0,1e-4\n0.0101,0,1e-4\n")
          .find("particles (numbered from 0 as read) 1 at (0.01    0) and 2 at (0.0101      0)"),
      std::string::npos)
      << message("x,y,volume\n0,0,1e-4\n0.01,0,1e-4\n0.0101,0,1e-4\n");
}

TEST(ParticleFile, AClampOnAFaceHoldsTheParticlesThere) {
  ScratchFolder dir;
  std::ofstream(dir.path / "set.csv") << "x,y,volume\n0,0,1\n0,1,1\n1,0,1\n1,1,1\n2,0.5,1\n";
  const auto setup = build<2>(sceneHead(2, 1.0) +
                                  "[body.b]\nshape = particles\nfile = set.csv\n[clamp.c]\nface "
                                  "= x-\nmethod = nodal\n",
                              dir.path / "s.ini");
  ASSERT_EQ(setup.scene.prescriptions.size(), 1u);
  const auto& held = setup.scene.prescriptions[0].particles;
  ASSERT_EQ(held.size(), 2u);
  for (Index i : held) {
    EXPECT_EQ(setup.scene.particles.referencePosition[i].x(), 0.0);
    EXPECT_EQ(setup.scene.particles.motion[i], Motion::Prescribed);
  }
  EXPECT_FALSE(setup.coarsen);  // a particle file cannot be rebuilt at a coarser dx
}

namespace {

// A lattice box's particles read from a file and clamped at a face (mirrored by default) give
// the lattice body's run: the ghosts are the same reflections, found from the plane where the
// particles' cells end rather than from the lattice (equal up to the rounding of that plane).
template <int D>
void expectMirroredClampAsTheLattice() {
  ScratchFolder dir;
  const std::string box = D == 2 ? "[body.block]\nshape = box\nlower = 0 0\nupper = 0.1 0.04\n"
                                 : "[body.block]\nshape = box\nlower = 0 0 0\nupper = 0.1 0.04 "
                                   "0.03\n";
  const std::string clamp = "[clamp.root]\nface = x-\n" + drive<D>();
  const double dx = 0.01;
  SceneSetup<D> lattice = build<D>(sceneHead(D, dx) + box + clamp, dir.path / "box.ini");
  std::vector<Vec<D>> X;
  std::vector<double> V;
  ParticleSet<D> body;
  for (Index i = 0; i < lattice.scene.particles.size(); ++i)
    if (!lattice.ghost[i])
      body.add(lattice.scene.particles.referencePosition[i], lattice.scene.particles.volume[i],
               lattice.scene.particles.mass[i], 0);
  writeCsv<D>(dir.path / "block.csv", body);
  SceneSetup<D> read =
      build<D>(sceneHead(D, dx) + "[body.block]\nshape = particles\nfile = block.csv\n" + clamp,
               dir.path / "read.ini");
  // The lattice adds ceil(H/dx) = 3 ghost layers; the file's clamp those within 3 spacings.
  ASSERT_EQ(read.scene.mirrorGhosts.size(), lattice.scene.mirrorGhosts.size());
  Solver<D> a(lattice.scene, lattice.solver), b(read.scene, read.solver);
  for (int k = 0; k < 40; ++k) {
    a.step();
    b.step();
  }
  double moved = 0.0, differs = 0.0;
  const auto& pa = lattice.scene.particles;
  const auto& pb = read.scene.particles;
  for (Index i = 0; i < pb.size(); ++i) {
    if (read.ghost[i]) continue;
    // The same body particle in both (both numbered by locality, ghosts after the body).
    ASSERT_EQ(pb.referencePosition[i], pa.referencePosition[i]);
    moved = std::max(moved, pa.displacement[i].norm());
    differs = std::max(differs, (pb.displacement[i] - pa.displacement[i]).norm());
  }
  EXPECT_GT(moved, 1e-4);
  EXPECT_LT(differs, 1e-12 * moved);
}

}  // namespace

TEST(ParticleFile, AMirroredClampRunsAsTheLatticeBodysClamp2D) {
  expectMirroredClampAsTheLattice<2>();
}
TEST(ParticleFile, AMirroredClampRunsAsTheLatticeBodysClamp3D) {
  expectMirroredClampAsTheLattice<3>();
}

// A particle set off the lattice takes support 2.5 unless the scene gives one; a lattice's
// set keeps 2.1; two overlapping clouds are refused.
TEST(ParticleFile, OffTheLatticeTheSupportWidensAndOverlapsAreRefused) {
  ScratchFolder dir;
  std::ofstream lattice(dir.path / "lattice.csv"), moved(dir.path / "moved.csv"),
      doubled(dir.path / "doubled.csv");
  for (auto* f : {&lattice, &moved, &doubled})
    *f << "x,y,volume\n" << std::setprecision(17);
  for (int i = 0; i < 10; ++i)
    for (int j = 0; j < 6; ++j) {
      const double x = (i + 0.5) * 0.01, y = (j + 0.5) * 0.01;
      lattice << x << "," << y << ",1e-4\n";
      doubled << x << "," << y << ",1e-4\n";
      moved << x + 0.0005 * ((i * 7 + j * 3) % 5 - 2) / 2.0 << "," << y << ",1e-4\n";
      if (i > 0 && j > 0) doubled << i * 0.01 << "," << j * 0.01 << ",1e-4\n";
    }
  lattice.close();
  moved.close();
  doubled.close();
  auto support = [&](const std::string& file, const std::string& extra = "") {
    return build<2>(
               sceneHead(2, 0.01) + "[body.b]\nshape = particles\nfile = " + file + "\n" + extra,
               dir.path / "s.ini")
               .scene.supportRadius /
           0.01;
  };
  EXPECT_NEAR(support("lattice.csv"), 2.1, 1e-12);
  EXPECT_NEAR(support("moved.csv"), kOffLatticeSupportRatio, 1e-12);
  EXPECT_NEAR(support("moved.csv", "[kernel]\nsupport = 2.2\n"), 2.2, 1e-12);
  try {
    support("doubled.csv");
    ADD_FAILURE() << "two clouds over the same space were accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("the file's particles overlap"), std::string::npos)
        << e.what();
  }
}

// The volume density is about 1 inside a lattice and 2 where two lattices overlap; the lattice
// test accepts rounding and refuses a shift of 1e-3 of the spacing.
TEST(ParticleSetChecks, DensityAndLattice) {
  std::vector<Vec<2>> X, Y;
  std::vector<double> V, W;
  for (int i = 0; i < 20; ++i)
    for (int j = 0; j < 20; ++j) {
      X.push_back(Vec<2>((i + 0.5) * 0.1, (j + 0.5) * 0.1));
      V.push_back(0.01);
    }
  const Kernel<2> kernel(KernelType::WendlandC2, 0.21);
  const auto rho = volumeDensity<2>(X, V, kernel, buildNeighbourList<2>(X, 0.21));
  EXPECT_NEAR(rho[10 * 20 + 10], 1.0, 0.05);  // inside
  // Half a spacing inside a face the kernel reaches across it: 0.88.
  EXPECT_GT(rho[0 * 20 + 10], 0.5);
  EXPECT_LT(rho[0 * 20 + 10], 0.95);
  Y = X;
  W = V;
  for (int i = 0; i < 20; ++i)
    for (int j = 0; j < 20; ++j) {
      Y.push_back(Vec<2>((i + 1.0) * 0.1, (j + 1.0) * 0.1));
      W.push_back(0.01);
    }
  EXPECT_NEAR(densityPeak<2>(Y, W, kernel, buildNeighbourList<2>(Y, 0.21)).density, 2.0, 0.1);
  EXPECT_TRUE(onCellCentredLattice<2>(X, V));
  auto shifted = X;
  shifted[7].x() += 1e-9;
  EXPECT_TRUE(onCellCentredLattice<2>(shifted, V));
  shifted[7].x() += 1e-4;
  EXPECT_FALSE(onCellCentredLattice<2>(shifted, V));
  EXPECT_NEAR(closestPair<2>(X, V, buildNeighbourList<2>(X, 0.21)).ratio, 1.0, 1e-12);
}

namespace {

const std::string kGeometry = std::string(TLSPH_SOURCE_DIR) + "/tests/geometry/data/";

template <int D>
Vec<D> totalForce(const Load<D>& load) {
  Vec<D> sum = Vec<D>::Zero();
  for (const auto& f : load.force)
    sum += f;
  return sum;
}

}  // namespace

// A pressure on a flat face adds up to p times its area along the inward normal; on the closed
// bore its shares cancel; the magnitudes add up to the surface's area.
TEST(MeshBody, PressureOnANamedSurfaceAddsUpToPTimesTheArea3D) {
  ScratchFolder dir;
  const double p = 2.5e5;
  const auto setup = build<3>(sceneHead(3, 0.5) + "[body.b]\nshape = mesh\nfile = " + kGeometry +
                                  "box_hole.geo\n[load.top]\nsurface = top\ntype = pressure\n"
                                  "value = 2.5e5\n[load.bore]\nsurface = bore\ntype = pressure\n"
                                  "value = 2.5e5\n",
                              dir.path / "s.ini");
  ASSERT_EQ(setup.scene.loads.size(), 2u);
  const auto& top = setup.surfaces.at("top");
  const Vec<3> onTop = totalForce(setup.scene.loads[0]);
  EXPECT_NEAR(onTop.z(), -p * top.measure, 1e-12 * p * top.measure);
  EXPECT_NEAR(onTop.head<2>().norm(), 0.0, 1e-12 * p * top.measure);
  // The order-2 surface's area against the exact 4 x 4 - pi.
  EXPECT_NEAR(top.measure, 16.0 - std::numbers::pi, 1e-3);
  for (Index i : setup.scene.loads[0].particles)
    EXPECT_EQ(setup.scene.particles.referencePosition[i].z(), 2.0);
  const auto& bore = setup.surfaces.at("bore");
  EXPECT_LT(totalForce(setup.scene.loads[1]).norm(), 1e-12 * p * bore.measure);
  double magnitudes = 0.0, areas = 0.0;
  for (std::size_t k = 0; k < bore.particles.size(); ++k) {
    magnitudes += bore.areaVector[k].norm();
    areas += bore.area[k];
    // The bore's normal points into the hole, towards its axis.
    const Vec<3> X = setup.scene.particles.referencePosition[bore.particles[k]];
    EXPECT_LT(bore.areaVector[k].head<2>().dot((X - Vec<3>(2, 2, 0)).head<2>()), 0.0);
  }
  EXPECT_NEAR(areas, bore.measure, 1e-12 * bore.measure);
  // |a_I| < A_I where the normal turns within a particle's share, by about (h/R)^2/12 for facets
  // of length h on a radius R (h <= 0.5 here, R = 1).
  EXPECT_LT(magnitudes, areas);
  EXPECT_GT(magnitudes, (1.0 - 0.5 * 0.5 / 6.0) * areas);
  EXPECT_NEAR(bore.measure, 2 * std::numbers::pi * 2.0, 1e-3 * bore.measure);
}

TEST(MeshBody, PressureOnANamedCurveAddsUpToPTimesTheLength2D) {
  ScratchFolder dir;
  const auto setup = build<2>(sceneHead(2, 0.25) + "[body.b]\nshape = mesh\nfile = " + kGeometry +
                                  "ring.geo\n[load.in]\nsurface = bore\n"
                                  "type = pressure\nvalue = 1e6\n",
                              dir.path / "s.ini");
  const auto& bore = setup.surfaces.at("bore");
  EXPECT_LT(totalForce(setup.scene.loads[0]).norm(), 1e-12 * 1e6 * bore.measure);
  double magnitudes = 0.0;
  for (std::size_t k = 0; k < bore.particles.size(); ++k) {
    const Vec<2> X = setup.scene.particles.referencePosition[bore.particles[k]];
    EXPECT_NEAR(X.norm(), 1.0, 1e-12);
    // On a circle the vector area points exactly along the radius, inwards.
    EXPECT_NEAR(std::abs(bore.areaVector[k].normalized().dot(X)), 1.0, 1e-12);
    EXPECT_LT(bore.areaVector[k].dot(X), 0.0);
    // A pressure in the bore pushes its particles outwards.
    EXPECT_GT(setup.scene.loads[0].force[k].dot(X), 0.0);
    magnitudes += bore.areaVector[k].norm();
  }
  EXPECT_NEAR(bore.measure, 2 * std::numbers::pi, 1e-4);
  EXPECT_LT(magnitudes, bore.measure);  // as in 3D, h <= 0.25 on R = 1
  EXPECT_GT(magnitudes, (1.0 - 0.25 * 0.25 / 6.0) * bore.measure);
}

TEST(MeshBody, AClampOnANamedSurfaceHoldsItsParticles) {
  ScratchFolder dir;
  const auto setup = build<3>(sceneHead(3, 0.5) + "[body.b]\nshape = mesh\nfile = " + kGeometry +
                                  "box_hole.geo\n[clamp.c]\nsurface = bottom\n",
                              dir.path / "s.ini");
  ASSERT_EQ(setup.scene.prescriptions.size(), 1u);
  const auto& held = setup.scene.prescriptions[0].particles;
  EXPECT_EQ(held, setup.surfaces.at("bottom").particles);
  std::size_t atBottom = 0;
  for (Index i = 0; i < setup.scene.particles.size(); ++i)
    atBottom += setup.scene.particles.referencePosition[i].z() == 0.0;
  EXPECT_EQ(held.size(), atBottom);
  for (Index i : held)
    EXPECT_EQ(setup.scene.particles.motion[i], Motion::Prescribed);
  // The volumes add up to the solid's (4 x 4 - pi) x 2 on the order-2 geometry.
  double volume = 0.0;
  for (Index i = 0; i < setup.scene.particles.size(); ++i)
    volume += setup.scene.particles.volume[i];
  EXPECT_NEAR(volume, (16.0 - std::numbers::pi) * 2.0, 1e-3 * volume);
}

TEST(MeshBody, ErrorsNameTheSurfaceAndTheChoices) {
  ScratchFolder dir;
  auto message = [&](const std::string& text) {
    try {
      build<3>(sceneHead(3, 0.5) + text, dir.path / "s.ini");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  const std::string body = "[body.b]\nshape = mesh\nfile = " + kGeometry + "box_hole.geo\n";
  const std::string unknown = message(body + "[clamp.c]\nsurface = side\n");
  EXPECT_NE(unknown.find("[clamp.c] surface"), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("bore"), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("bottom"), std::string::npos) << unknown;
  EXPECT_NE(message(body + "[load.l]\nsurface = top\nface = z+\ntype = pressure\nvalue = 1\n")
                .find("not both"),
            std::string::npos);
  EXPECT_NE(message("[body.b]\nshape = box\nlower = 0 0 0\nupper = 1 1 1\n[clamp.c]\nsurface = "
                    "top\n")
                .find("surface"),
            std::string::npos);
  const std::string missing = message("[body.b]\nshape = mesh\nfile = nowhere.step\n");
  EXPECT_NE(missing.find("[body.b] file"), std::string::npos) << missing;
  EXPECT_NE(missing.find("nowhere.step"), std::string::npos) << missing;
}

// A meshed body's particles carry their nodes' hat moments (GmshBody.hpp) in their new
// numbering: the nodes' sum is the strip's first and second moments; a particle file's carry
// none (lattice cells).
TEST(MeshedBody, ParticlesCarryTheirNodesMoments) {
  ScratchFolder dir;
  std::ofstream(dir.path / "strip.geo")
      << "Point(1) = {0, 0, 0};\nPoint(2) = {0.1, 0, 0};\nPoint(3) = {0.1, 0.02, 0};\n"
         "Point(4) = {0, 0.02, 0};\nLine(1) = {1, 2};\nLine(2) = {2, 3};\nLine(3) = {3, 4};\n"
         "Line(4) = {4, 1};\nCurve Loop(1) = {1, 2, 3, 4};\nPlane Surface(1) = {1};\n";
  const auto setup = build<2>(
      sceneHead(2, 0.005) + "[body.b]\nshape = mesh\nfile = strip.geo\nrecombine = false\n",
      dir.path / "s.ini");
  const auto& p = setup.scene.particles;
  ASSERT_EQ(p.quadratureOffset.size(), std::size_t(p.size()));
  ASSERT_EQ(p.quadratureSpread.size(), std::size_t(p.size()));
  Vec<2> first = Vec<2>::Zero();
  Mat<2> second = Mat<2>::Zero();
  double offset = 0.0;
  for (Index i = 0; i < p.size(); ++i) {
    const Vec<2>& X = p.referencePosition[i];
    const Vec<2>& mu = p.quadratureOffset[i];
    first += p.volume[i] * (X + mu);
    second += p.volume[i] *
              (X * X.transpose() + mu * X.transpose() + X * mu.transpose() + p.quadratureSpread[i]);
    offset = std::max(offset, mu.norm());
  }
  const double A = 0.1 * 0.02;
  EXPECT_LT((first - A * Vec<2>(0.05, 0.01)).norm(), 1e-12 * A * 0.05);
  Mat<2> exact;
  exact << A * 0.01 / 3, A * 0.05 * 0.01, A * 0.05 * 0.01, A * 0.0004 / 3;
  EXPECT_LT((second - exact).norm(), 1e-12 * exact.norm());
  EXPECT_GT(offset, 0.1 * 0.005);  // the surface nodes' hats lean into the strip

  std::ofstream(dir.path / "set.csv") << "x,y,volume\n0,0,1\n0,1,1\n1,0,1\n1,1,1\n";
  const auto read = build<2>(sceneHead(2, 1.0) + "[body.b]\nshape = particles\nfile = set.csv\n",
                             dir.path / "r.ini");
  EXPECT_TRUE(read.scene.particles.quadratureOffset.empty());
  EXPECT_TRUE(read.scene.particles.quadratureMoments().lattice());
}
