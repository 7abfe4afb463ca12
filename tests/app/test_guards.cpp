// The stability guards of `tlsph run` (src/app/Guards.hpp): set-ups made to go wrong in one
// way each stop with exit status 4 and the documented message (step, time, quantity and
// value, particle, likely cause), an "instability" record in summary.json, and the last good
// and failed states as VTU frames that VTK reads back; a healthy run does not trip them.
#include <gtest/gtest.h>
#include <vtkDataArray.h>
#include <vtkFieldData.h>
#include <vtkPointData.h>
#include <vtkSmartPointer.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLUnstructuredGridReader.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

#include "ProgramRunner.hpp"

namespace fs = std::filesystem;
using tlsph::testing::runProgram;

namespace {

// A 2D block 0.2 x 0.1 m (20 x 10 particles) clamped at x = 0, set moving upwards.
constexpr const char* kBlock2D = R"(
[scene]
dimension = 2
dx = 0.01
[material.m]
model = neo-hookean
density = 1000
youngs_modulus = 1e6
poisson_ratio = 0.3
[body.block]
shape = box
lower = 0 0
upper = 0.2 0.1
[clamp.root]
face = x-
[initial.push]
velocity = 0 0.1
[time]
end = 0.5
[output]
fields = none
)";

// A 2D block 0.1 x 0.1 m clamped at the bottom; its top layer is driven down at 20 m/s,
// 0.55 of the wave speed: it runs through the block within a few hundred steps.
constexpr const char* kCrush2D = R"(
[scene]
dimension = 2
dx = 0.01
[material.m]
model = saint-venant-kirchhoff
density = 1000
youngs_modulus = 1e6
poisson_ratio = 0.3
[body.block]
shape = box
lower = 0 0
upper = 0.1 0.1
[clamp.bottom]
face = y-
[region.top]
shape = half-space
point = 0 0.09
normal = 0 1
[prescribe.press]
region = top
motion = velocity
value = 0 -20
[time]
end = 0.01
[output]
fields = none
)";

// An undamped 3D cantilever 0.4 x 0.08 x 0.08 m (20 x 4 x 4 particles) swinging in its first
// mode with the textbook Ganzenmueller hourglass force: its work turns negative and grows.
// The textbook penalty feeds energy into this swing at the nodal quadrature (hourglass energy
// below zero after about 0.9 s); with the Taylor quadrature it ran 8 s without.
constexpr const char* kSwing3D = R"(
[scene]
dimension = 3
dx = 0.02
[material.m]
model = neo-hookean
density = 1000
youngs_modulus = 1e6
poisson_ratio = 0.3
[body.beam]
shape = box
lower = 0 0 0
upper = 0.4 0.08 0.08
[clamp.root]
face = x-
[initial.mode]
profile = beam-mode
axis = x
origin = 0
length = 0.4
direction = 0 0 1
amplitude = 1
[kernel]
quadrature = nodal
[hourglass]
form = ganzenmueller
alpha = 10
[time]
end = 2
[output]
fields = none
)";

std::string readText(const fs::path& file) {
  std::ifstream in(file);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// What the guard printed: `tlsph: unstable at step N, t = T s: WHAT at particle I (X = ...):`
// and, indented on the next line, the likely cause.
struct GuardMessage {
  long step = -1;
  double time = -1.0;
  std::string what, particle, position, cause;
};

GuardMessage parseMessage(const std::string& output) {
  static const std::regex form(
      R"(tlsph: unstable at step (\d+), t = (\S+) s: (.+) at particle (\d+) \(X = ([^)]+)\):\n  (likely .+)\n)");
  std::smatch m;
  GuardMessage g;
  if (!std::regex_search(output, m, form)) return g;
  g.step = std::stol(m[1]);
  g.time = std::stod(m[2]);
  g.what = m[3];
  g.particle = m[4];
  g.position = m[5];
  g.cause = m[6];
  return g;
}

class Guards : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("tlsph_guards_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
            "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    if (!HasFailure()) fs::remove_all(dir_);
  }

  // Runs the scene `text` (written as DIR/NAME.ini) with the overrides; output in DIR/out.
  tlsph::testing::ProgramResult run(const std::string& name, const std::string& text,
                                    const std::string& overrides = "") {
    const fs::path scene = dir_ / (name + ".ini");
    std::ofstream(scene) << text;
    return runProgram("run " + scene.string() +
                          " --no-progress --output.directory=" + out().string() + " " + overrides,
                      dir_ / (name + ".log"));
  }
  fs::path out() const { return dir_ / "out"; }

  // Exit status 4, the message in its documented form, summary.json's record, and both
  // frames readable by VTK with every output field; returns the parsed message.
  GuardMessage expectUnstable(const tlsph::testing::ProgramResult& r, const std::string& name,
                              const std::string& quantity, long points) {
    EXPECT_EQ(r.status, 4) << r.output;
    const GuardMessage g = parseMessage(r.output);
    EXPECT_GT(g.step, 0) << "no guard message in the form documented:\n" << r.output;
    std::cout << "stderr: " << r.output.substr(r.output.find("tlsph: unstable"));

    const std::string record = readText(out() / "summary.json");
    EXPECT_NE(record.find("\"outcome\": \"unstable\""), std::string::npos) << record;
    EXPECT_NE(record.find("\"instability\": {\"step\": " + std::to_string(g.step) + ","),
              std::string::npos)
        << record;
    EXPECT_NE(record.find("\"quantity\": \"" + quantity + "\""), std::string::npos) << record;
    for (const char* key : {"\"time\":", "\"value\":", "\"particle\": ",
                            "\"reference_position\": [", "\"cause\": \"likely"})
      EXPECT_NE(record.find(key), std::string::npos) << key << "\n" << record;

    for (const char* which : {"_failed.vtu", "_last_good.vtu"}) {
      const fs::path frame = out() / (name + which);
      EXPECT_NE(r.output.find("wrote        " + frame.string()), std::string::npos) << r.output;
      EXPECT_TRUE(fs::exists(frame)) << frame;
      if (!fs::exists(frame)) continue;
      auto reader = vtkSmartPointer<vtkXMLUnstructuredGridReader>::New();
      reader->SetFileName(frame.c_str());
      reader->Update();
      vtkUnstructuredGrid* grid = reader->GetOutput();
      EXPECT_EQ(grid->GetNumberOfPoints(), points) << frame;
      for (const char* field : {"displacement", "velocity", "J", "von_mises", "cauchy_stress",
                                "first_piola", "hourglass_error", "ghost", "prescribed", "body"})
        EXPECT_NE(grid->GetPointData()->GetArray(field), nullptr) << frame << ": " << field;
      vtkDataArray* step = grid->GetFieldData()->GetArray("STEP");
      EXPECT_NE(step, nullptr);
      // The last good state is that of the check before the failing one.
      if (step && std::string(which) == "_failed.vtu") {
        EXPECT_EQ(step->GetTuple1(0), g.step);
      }
      if (step && std::string(which) == "_last_good.vtu") {
        EXPECT_LT(step->GetTuple1(0), g.step);
      }
    }
    // The last good state is finite everywhere.
    auto reader = vtkSmartPointer<vtkXMLUnstructuredGridReader>::New();
    reader->SetFileName((out() / (name + "_last_good.vtu")).c_str());
    reader->Update();
    // and its body particles' stresses were re-evaluated for it (a mirrored clamp ghost
    // carries no stress in the solver and may show a NaN one in the frame).
    long nonFinite = 0;
    vtkDataArray* ghost = reader->GetOutput()->GetPointData()->GetArray("ghost");
    for (const char* field : {"displacement", "velocity", "J", "von_mises"}) {
      vtkDataArray* a = reader->GetOutput()->GetPointData()->GetArray(field);
      const bool all = std::string(field) == "displacement" || std::string(field) == "velocity";
      for (vtkIdType i = 0; a && ghost && i < a->GetNumberOfTuples(); ++i)
        for (int c = 0; c < a->GetNumberOfComponents(); ++c)
          nonFinite += (all || ghost->GetTuple1(i) == 0) && !std::isfinite(a->GetComponent(i, c));
    }
    EXPECT_EQ(nonFinite, 0);
    return g;
  }

  fs::path dir_;
};

}  // namespace

// A fixed step twice the predicted stable one (about 1.5 times the real limit), checked at
// every step: the energy books notice the growth before anything is NaN.
TEST_F(Guards, StepAboveTheStableStepTripsTheEnergyBalance) {
  const auto r =
      run("block", kBlock2D, "--time.dt=2.5e-4 --static.enabled=false --static.check_every=1");
  const GuardMessage g = expectUnstable(r, "block", "energy_balance_error", 230);
  EXPECT_NE(g.what.find("energy balance error E - E0 = "), std::string::npos) << g.what;
  EXPECT_NE(g.what.find("of the energy scale"), std::string::npos) << g.what;
  EXPECT_NE(g.what.find("changed most since the last check"), std::string::npos) << g.what;
  EXPECT_NE(g.cause.find("likely the time step"), std::string::npos) << g.cause;
  EXPECT_NE(g.cause.find("predicted stable step"), std::string::npos) << g.cause;
  EXPECT_NE(g.cause.find("lower [time] dt"), std::string::npos) << g.cause;
}

// A fixed step 4 times the predicted stable one: NaN within the first check interval.
TEST_F(Guards, FarTooLargeFixedStepGoesNonFinite) {
  const auto r = run("block", kBlock2D, "--time.dt=5e-4");
  const GuardMessage g = expectUnstable(r, "block", "displacement", 230);
  EXPECT_EQ(g.step, 50);
  EXPECT_NE(g.what.find("non-finite displacement"), std::string::npos) << g.what;
  EXPECT_NE(g.cause.find("likely the time step"), std::string::npos) << g.cause;
  EXPECT_NE(g.cause.find("lower [time] dt"), std::string::npos) << g.cause;
}

// Saint Venant-Kirchhoff stays finite when inverted, so the J check sees the inversion.
TEST_F(Guards, PrescribedFaceDrivenThroughTheBodyInvertsIt) {
  const auto r = run("crush", kCrush2D);
  const GuardMessage g = expectUnstable(r, "crush", "J", 130);
  EXPECT_NE(g.what.find("J = det F = -"), std::string::npos) << g.what;
  EXPECT_NE(g.what.find("<= 0 (inverted material)"), std::string::npos) << g.what;
  EXPECT_NE(g.cause.find("likely loads or prescribed motion too large for the mesh / material "
                         "parameters"),
            std::string::npos)
      << g.cause;
}

// A neo-Hookean particle has NaN stress once inverted: between two checks the NaN spreads,
// and the diagnosis falls back on what the last good check showed (J already small next to
// the clamp) or on the drive (20 m/s against a 37 m/s wave speed).
TEST_F(Guards, InvertedNeoHookeanGoesNonFiniteAndBlamesTheDrive) {
  const auto r = run("crush", kCrush2D, "--material.m.model=neo-hookean");
  const GuardMessage g = expectUnstable(r, "crush", "displacement", 130);
  EXPECT_NE(g.what.find("non-finite displacement"), std::string::npos) << g.what;
  EXPECT_NE(g.cause.find("likely loads or prescribed motion too large for the mesh / material "
                         "parameters"),
            std::string::npos)
      << g.cause;
}

// [guard] min_jacobian stops a slower squeeze before the material collapses.
TEST_F(Guards, MinJacobianStopsACollapsingBlock) {
  const auto r = run("crush", kCrush2D,
                     "--material.m.model=neo-hookean --prescribe.press.value='0 -5' "
                     "--guard.min_jacobian=0.6");
  const GuardMessage g = expectUnstable(r, "crush", "J", 130);
  EXPECT_NE(g.what.find("<= 0.6 ([guard] min_jacobian: collapsed material)"), std::string::npos)
      << g.what;
  EXPECT_NE(g.cause.find("likely loads or prescribed motion too large"), std::string::npos)
      << g.cause;
  // Without the bound the same run finishes.
  fs::remove_all(out());
  const auto healthy =
      run("crush", kCrush2D, "--material.m.model=neo-hookean --prescribe.press.value='0 -5'");
  EXPECT_EQ(healthy.status, 0) << healthy.output;
}

TEST_F(Guards, GanzenmuellerHourglassFeedingEnergyIsNamed) {
  const auto r = run("swing", kSwing3D);
  const GuardMessage g = expectUnstable(r, "swing", "hourglass_energy", 20 * 4 * 4 + 3 * 4 * 4);
  EXPECT_NE(g.what.find("hourglass energy -"), std::string::npos) << g.what;
  EXPECT_NE(g.what.find("below zero by"), std::string::npos) << g.what;
  EXPECT_NE(g.cause.find("likely the hourglass term feeding energy in"), std::string::npos)
      << g.cause;
  EXPECT_NE(g.cause.find("use [hourglass] form = energy or a smaller alpha"), std::string::npos)
      << g.cause;
}

TEST_F(Guards, EnergyFormHourglassSwingsCleanly) {
  const auto r = run("swing", kSwing3D, "--hourglass.form=energy --time.end=1");
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(r.output.find("unstable"), std::string::npos) << r.output;
}

TEST_F(Guards, HealthyRunDoesNotTrip) {
  const auto r = runProgram("run " + std::string(TLSPH_SOURCE_DIR) +
                                "/examples/oscillating_plate.ini --time.end=0.3 --no-progress "
                                "--output.directory=" +
                                out().string(),
                            dir_ / "log.txt");
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(r.output.find("unstable"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(out() / "oscillating_plate_failed.vtu"));
  EXPECT_FALSE(fs::exists(out() / "oscillating_plate_last_good.vtu"));
  const std::string record = readText(out() / "summary.json");
  EXPECT_NE(record.find("\"outcome\": \"finished\""), std::string::npos) << record;
  EXPECT_EQ(record.find("\"instability\""), std::string::npos) << record;
}

TEST_F(Guards, BadGuardKeysAreInputErrors) {
  const auto r = run("block", kBlock2D, "--guard.min_jacobian=1.5");
  EXPECT_EQ(r.status, 1) << r.output;
  EXPECT_NE(r.output.find("[guard] min_jacobian: must be in [0, 1)"), std::string::npos)
      << r.output;
  const auto negative = run("block", kBlock2D, "--guard.energy_error=-1");
  EXPECT_EQ(negative.status, 1) << negative.output;
  EXPECT_NE(negative.output.find("[guard] energy_error"), std::string::npos) << negative.output;
}
