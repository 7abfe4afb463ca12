// Checkpoint/restart: a run stopped at a random step and restarted from its
// checkpoint ends bit for bit where the uninterrupted run ends (CSV series, VTU frames, PVD
// index), in 2D and 3D, dynamic, damped static and Newton static; SIGTERM leaves a usable
// checkpoint; foreign, damaged and mismatched checkpoints are refused with a message; the
// output directory is protected (--overwrite) and a failed write stops the run cleanly.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "ProgramRunner.hpp"
#include "app/Checkpoint.hpp"
#include "app/OutputDirectory.hpp"
#include "io/CheckpointArchive.hpp"
#include "output/CsvSeries.hpp"

namespace fs = std::filesystem;
using tlsph::testing::runProgram;

namespace {

std::string readFile(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// A CSV file without its "# command:" line (which names the run's output directory).
std::string withoutCommand(const std::string& text) {
  std::string out;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("# command: ", 0) != 0) out += line + "\n";
  return out;
}

// Every CSV, VTU and PVD file of run `a`, compared byte for byte with run `b`'s (CSV files
// apart from the command line in their preamble).
void expectSameOutput(const fs::path& a, const fs::path& b) {
  int compared = 0;
  for (const auto& entry : fs::directory_iterator(a)) {
    const auto ext = entry.path().extension();
    if (ext != ".csv" && ext != ".vtu" && ext != ".pvd") continue;
    const fs::path other = b / entry.path().filename();
    ASSERT_TRUE(fs::exists(other)) << other;
    if (ext == ".csv")
      EXPECT_TRUE(withoutCommand(readFile(entry.path())) == withoutCommand(readFile(other)))
          << entry.path().filename() << " differs after the restart";
    else
      EXPECT_TRUE(readFile(entry.path()) == readFile(other))
          << entry.path().filename() << " differs after the restart";
    ++compared;
  }
  for (const auto& entry : fs::directory_iterator(b)) {
    const auto ext = entry.path().extension();
    if (ext == ".csv" || ext == ".vtu" || ext == ".pvd") {
      EXPECT_TRUE(fs::exists(a / entry.path().filename()))
          << entry.path().filename() << " only in the restarted run";
    }
  }
  EXPECT_GE(compared, 1);
}

std::vector<fs::path> checkpointsIn(const fs::path& dir) {
  std::vector<fs::path> files;
  if (fs::is_directory(dir / "checkpoints"))
    for (const auto& entry : fs::directory_iterator(dir / "checkpoints"))
      files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  return files;
}

class CheckpointRestart : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("tlsph_restart_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
            "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string scene(const std::string& relative) const {
    return std::string(TLSPH_SOURCE_DIR) + "/" + relative;
  }

  // Runs `arguments` uninterrupted into `full`, with a checkpoint every `every` steps; copies
  // the output as it stands at the end (later rows and frames included, as a crash leaves them)
  // and restarts the copy from the checkpoint at step `every`; the two must be identical.
  void restartMatches(const std::string& arguments, long every, int restartThreads = 0) {
    const fs::path full = dir_ / "full", cont = dir_ / "continued";
    const std::string common = arguments + " --checkpoint.every_steps=" + std::to_string(every) +
                               " --checkpoint.keep=1000";
    auto r = runProgram("run " + common + " --output.directory=" + full.string(), dir_ / "a.log");
    ASSERT_EQ(r.status, 0) << r.output;
    const auto checkpoints = checkpointsIn(full);
    ASSERT_GE(checkpoints.size(), 2u) << r.output;  // one to restart from, and a later one
    fs::copy(full, cont, fs::copy_options::recursive);
    // The restart on another thread count (results do not depend on it).
    const char* before = std::getenv("OMP_NUM_THREADS");
    const std::string saved = before ? before : "";
    if (restartThreads > 0) {
      ::setenv("OMP_NUM_THREADS", std::to_string(restartThreads).c_str(), 1);
      ::setenv("OMP_WAIT_POLICY", "passive", 1);
    }
    const fs::path from = cont / "checkpoints" / checkpoints.front().filename();
    r = runProgram(
        "run " + common + " --output.directory=" + cont.string() + " --restart=" + from.string(),
        dir_ / "b.log");
    if (restartThreads > 0) {
      if (before)
        ::setenv("OMP_NUM_THREADS", saved.c_str(), 1);
      else
        ::unsetenv("OMP_NUM_THREADS");
      ::unsetenv("OMP_WAIT_POLICY");
    }
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("restart      from"), std::string::npos) << r.output;
    expectSameOutput(full, cont);
  }

  fs::path dir_;
};

long randomStep(long lo, long hi) {
  std::random_device device;
  std::uniform_int_distribution<long> pick(lo, hi);
  const long step = pick(device);
  std::cout << "checkpoint interval (random): " << step << " steps\n";
  return step;
}

TEST_F(CheckpointRestart, Dynamic3DContinuesBitForBit) {
  restartMatches(scene("examples/hourglass_block.ini"), randomStep(50, 400));
}

// A checkpoint written on one thread continues on three to the same bits (nothing in a run
// depends on the thread count: test_thread_independence).
TEST_F(CheckpointRestart, RestartOnAnotherThreadCountContinuesBitForBit) {
  restartMatches(scene("examples/hourglass_block.ini"), randomStep(50, 400), 3);
}

TEST_F(CheckpointRestart, NewtonRestartOnAnotherThreadCountContinuesBitForBit) {
  restartMatches(scene("validation/scenes/cantilever_large.ini") +
                     " --scene.dx=0.025 --static.solver=newton --static.load_steps=4",
                 2, 2);
}

TEST_F(CheckpointRestart, Dynamic2DContinuesBitForBit) {
  // Probes, a prescribed root and artificial viscosity (which reads the mid-step velocities).
  restartMatches(scene("examples/oscillating_plate.ini") +
                     " --time.end=0.02 --output.every_time=0.002"
                     " --artificial_viscosity.linear=1 --artificial_viscosity.quadratic=2",
                 randomStep(100, 900));
}

TEST_F(CheckpointRestart, DampedStatic3DContinuesBitForBit) {
  // Kinetic damping, mirrored clamp, gravity ramp; the run stops on its residual (after about
  // 10,600 steps at this resolution: checkpoints at most every 4000 steps leave two of them).
  restartMatches(scene("examples/cantilever.ini") +
                     " --static.solver=damped --scene.dx=0.025 --output.every_time=0.05",
                 randomStep(500, 4000));
}

TEST_F(CheckpointRestart, NewtonStatic2DContinuesBitForBit) {
  restartMatches(scene("validation/scenes/cook_membrane.ini") +
                     " --scene.dx=0.004 --static.solver=newton --static.load_steps=3",
                 1);
}

TEST_F(CheckpointRestart, NewtonStatic3DNonlinearContinuesBitForBit) {
  // Large deflection: several Newton iterations per load step, a preconditioner renewed on the
  // way (its state is rebuilt from the F saved in the checkpoint).
  restartMatches(scene("validation/scenes/cantilever_large.ini") +
                     " --scene.dx=0.025 --static.solver=newton --static.load_steps=4",
                 randomStep(1, 2));
}

TEST_F(CheckpointRestart, NewtonMultigridContinuesBitForBit) {
  // The multigrid's coarse level and smoother are rebuilt from the load time, displacements,
  // F and second gradients saved at its last renewal; the restart runs on another thread count.
  restartMatches(scene("validation/scenes/cantilever_large.ini") +
                     " --scene.dx=0.025 --static.solver=newton --static.load_steps=4"
                     " --static.preconditioner=multigrid",
                 randomStep(1, 2), 2);
}

// A following pressure is evaluated on the restored displacements: the Lame ring in rubber
// under a following pressure in its bore, undamped, and solved by Newton in load steps.
TEST_F(CheckpointRestart, FollowingPressureDynamicContinuesBitForBit) {
  restartMatches(scene("validation/scenes/lame_ring.ini") +
                     " --scene.dx=0.0125 --load.p.follow=true --load.p.value=1e5"
                     " --material.steel.model=neo-hookean --material.steel.youngs_modulus=1e6"
                     " --material.steel.density=1000 --static.enabled=false --time.end=0.02"
                     " --damping.kinetic=false --output.every_time=0.005",
                 randomStep(20, 80));
}

TEST_F(CheckpointRestart, FollowingPressureNewtonContinuesBitForBit) {
  restartMatches(scene("validation/scenes/lame_ring.ini") +
                     " --scene.dx=0.0125 --load.p.follow=true --load.p.value=1e5 --load.p.ramp=1"
                     " --material.steel.model=neo-hookean --material.steel.youngs_modulus=1e6"
                     " --material.steel.density=1000 --static.load_steps=3",
                 1);
}

// SIGTERM at a random moment once the run has begun (its first series written): exit 143 with a
// checkpoint; restarting from it ('latest') ends exactly where the uninterrupted run ends.
TEST_F(CheckpointRestart, TerminatedRunRestartsFromItsCheckpoint) {
  const std::string args =
      scene("examples/hourglass_block.ini") + " --time.end=0.15 --output.every_time=0.01";
  const fs::path full = dir_ / "full", cut = dir_ / "cut";
  auto r = runProgram("run " + args + " --output.directory=" + full.string(), dir_ / "a.log");
  ASSERT_EQ(r.status, 0) << r.output;

  std::random_device device;
  const int delayMs = std::uniform_int_distribution<int>(200, 700)(device);
  const std::string command =
      "sh -c '" + std::string(TLSPH_PROGRAM) + " run " + args +
      " --output.directory=" + cut.string() + " > " + (dir_ / "b.log").string() +
      " 2>&1 & pid=$!; while [ ! -f " + (cut / "energies.csv").string() +
      " ]; do sleep 0.02; done; sleep " + std::to_string(delayMs / 1000.0) +
      "; kill -TERM $pid; wait $pid; echo $? > " + (dir_ / "status").string() + "'";
  ASSERT_EQ(std::system(command.c_str()), 0);
  int status = -1;
  std::ifstream(dir_ / "status") >> status;
  const std::string log = readFile(dir_ / "b.log");
  if (status == 0) GTEST_SKIP() << "the run finished before the signal (" << delayMs << " ms)";
  ASSERT_EQ(status, 143) << log;
  EXPECT_NE(log.find("--restart="), std::string::npos) << log;
  ASSERT_EQ(checkpointsIn(cut).size(), 1u) << log;

  r = runProgram("run " + args + " --output.directory=" + cut.string() + " --restart=latest",
                 dir_ / "c.log");
  ASSERT_EQ(r.status, 0) << r.output;
  expectSameOutput(full, cut);
}

TEST_F(CheckpointRestart, ForeignCheckpointsAreRefused) {
  const std::string args = scene("examples/hourglass_block.ini") + " --time.end=0.002";
  const fs::path out = dir_ / "out";
  auto r =
      runProgram("run " + args + " --checkpoint.every_steps=20 --output.directory=" + out.string(),
                 dir_ / "a.log");
  ASSERT_EQ(r.status, 0) << r.output;
  const auto checkpoints = checkpointsIn(out);
  ASSERT_FALSE(checkpoints.empty());
  const std::string ckpt = checkpoints.back().string();

  // Another scene (a changed modulus): the first difference is named.
  r = runProgram("run " + args + " --material.rubber.youngs_modulus=2e6 --output.directory=" +
                     out.string() + " --restart=" + ckpt,
                 dir_ / "b.log");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.output.find("cannot restart from checkpoint"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("[material.rubber] youngs_modulus"), std::string::npos) << r.output;

  // Another scene file altogether (2D).
  r = runProgram("run " + scene("examples/oscillating_plate.ini") +
                     " --output.directory=" + (dir_ / "other").string() + " --restart=" + ckpt,
                 dir_ / "c.log");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.output.find("cannot restart from checkpoint"), std::string::npos) << r.output;

  // Not a checkpoint; a damaged one; a missing one; no checkpoint at all for 'latest'.
  const fs::path garbage = dir_ / "garbage.ckpt";
  std::ofstream(garbage) << "[scene]\ndimension = 3\n";
  r = runProgram(
      "run " + args + " --output.directory=" + out.string() + " --restart=" + garbage.string(),
      dir_ / "d.log");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.output.find("not a tlsph checkpoint"), std::string::npos) << r.output;

  std::string bytes = readFile(ckpt);
  bytes[bytes.size() / 2] ^= 0x5a;
  const fs::path damaged = dir_ / "damaged.ckpt";
  std::ofstream(damaged, std::ios::binary) << bytes;
  r = runProgram(
      "run " + args + " --output.directory=" + out.string() + " --restart=" + damaged.string(),
      dir_ / "e.log");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.output.find("damaged"), std::string::npos) << r.output;

  const fs::path truncated = dir_ / "truncated.ckpt";
  std::ofstream(truncated, std::ios::binary) << readFile(ckpt).substr(0, 100);
  r = runProgram(
      "run " + args + " --output.directory=" + out.string() + " --restart=" + truncated.string(),
      dir_ / "f.log");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.output.find("truncated"), std::string::npos) << r.output;

  r = runProgram("run " + args + " --output.directory=" + out.string() +
                     " --restart=" + (dir_ / "missing.ckpt").string(),
                 dir_ / "g.log");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.output.find("no such file"), std::string::npos) << r.output;

  r = runProgram(
      "run " + args + " --output.directory=" + (dir_ / "empty").string() + " --restart=latest",
      dir_ / "h.log");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.output.find("no checkpoint of scene"), std::string::npos) << r.output;
}

// A checkpoint records its particles as numbered and placed: a build of tlsph that numbers the
// same scene's particles otherwise (LocalityOrder.hpp) refuses it rather than continue the run
// with every particle's state on another particle.
TEST(CheckpointOrigin, ParticlesNumberedOtherwiseAreRefused) {
  using namespace tlsph;
  std::vector<Vec<2>> X = {Vec<2>(0.005, 0.005), Vec<2>(0.015, 0.005), Vec<2>(0.005, 0.015)};
  const std::string digest = particleDigest<2>(X);
  EXPECT_EQ(digest.rfind("3 particles, FNV-1a ", 0), 0u) << digest;
  EXPECT_EQ(particleDigest<2>(X), digest);  // a function of the positions only
  std::swap(X[1], X[2]);
  const std::string renumbered = particleDigest<2>(X);
  EXPECT_NE(renumbered, digest);
  X[2].x() = std::nextafter(X[2].x(), 1.0);  // one position's last bit
  EXPECT_NE(particleDigest<2>(X), renumbered);
  // The quadrature moments of a meshed body's particles count; none (lattice cells) add nothing.
  EXPECT_EQ(particleDigest<2>(X, {}), particleDigest<2>(X));
  std::vector<Vec<2>> offset(3, Vec<2>::Zero());
  std::vector<Mat<2>> spread(3, Mat<2>::Identity());
  const std::string withMoments = particleDigest<2>(X, {offset, spread});
  EXPECT_NE(withMoments, particleDigest<2>(X));
  spread[1](0, 1) = 1e-300;
  EXPECT_NE(particleDigest<2>(X, {offset, spread}), withMoments);

  CheckpointOrigin saved;
  saved.version = "0.1.0";
  saved.settings = {{"scene.dx", "0.01"}};
  saved.particles = digest;
  EXPECT_EQ(checkpointMismatch(saved, "0.1.0", saved.settings, digest), "");
  const std::string why = checkpointMismatch(saved, "0.1.0", saved.settings, renumbered);
  EXPECT_NE(why.find(digest), std::string::npos) << why;
  EXPECT_NE(why.find(renumbered), std::string::npos) << why;
  saved.particles.clear();  // a checkpoint of a tlsph that did not record them
  EXPECT_NE(checkpointMismatch(saved, "0.1.0", saved.settings, digest).find("does not record"),
            std::string::npos);
  // a changed setting is named first
  EXPECT_NE(checkpointMismatch(saved, "0.1.0", {{"scene.dx", "0.02"}}, digest).find("[scene] dx"),
            std::string::npos);
}

TEST(CheckpointArchive, RoundTripsBlocksAndRefusesDamage) {
  const fs::path file = fs::temp_directory_path() / "tlsph_archive_test.ckpt";
  tlsph::CheckpointWriter w;
  w.put("answer", std::int64_t(42));
  w.putVector("values", std::vector<double>{1.5, -2.25, 1e-300});
  w.putString("text", std::string("a\0b", 3));
  w.write(file);
  {
    const tlsph::CheckpointReader r(file);
    EXPECT_EQ(r.get<std::int64_t>("answer"), 42);
    EXPECT_EQ(r.getVector<double>("values"), (std::vector<double>{1.5, -2.25, 1e-300}));
    EXPECT_EQ(r.getString("text"), std::string("a\0b", 3));
    EXPECT_THROW(r.get<double>("missing"), tlsph::CheckpointError);
    EXPECT_THROW(r.get<std::int32_t>("answer"), tlsph::CheckpointError);  // wrong size
  }
  std::string bytes = readFile(file);
  for (std::size_t cut : {std::size_t(0), std::size_t(10), bytes.size() - 1}) {
    std::ofstream(file, std::ios::binary) << bytes.substr(0, cut);
    EXPECT_THROW(tlsph::CheckpointReader{file}, tlsph::CheckpointError) << cut;
  }
  fs::remove(file);
}

// A continued series keeps its comment lines and the rows before the checkpoint only.
TEST(CsvSeriesResume, KeepsTheRowsBeforeTheCheckpoint) {
  const fs::path file = fs::temp_directory_path() / "tlsph_resume_test.csv";
  {
    tlsph::CsvSeries s(file, {"time", "value"});
    s.setPreamble({"first run"});
    for (int k = 0; k < 5; ++k)
      s.append({double(k), 10.0 * k});
    s.flush();
  }
  tlsph::CsvSeries s(file, {"time", "value"});
  s.setPreamble({"second run"});
  s.resume(3);
  s.append({3.5, 35.0});
  s.flush();
  EXPECT_EQ(readFile(file), "# first run\ntime,value\n0,0\n1,10\n2,20\n3.5,35\n");
  EXPECT_EQ(s.rowCount(), 4u);

  tlsph::CsvSeries other(file, {"time", "other"});
  EXPECT_THROW(other.resume(1), std::runtime_error);  // another header
  tlsph::CsvSeries more(file, {"time", "value"});
  EXPECT_THROW(more.resume(10), std::runtime_error);  // fewer rows than the checkpoint's
  fs::remove(file);
}

// An earlier run's output is not replaced without --overwrite; with it, its stale files go.
TEST_F(CheckpointRestart, OutputDirectoryOfAnEarlierRunNeedsOverwrite) {
  const std::string args =
      scene("examples/hourglass_block.ini") + " --output.directory=" + (dir_ / "out").string();
  auto r =
      runProgram("run " + args + " --time.end=0.004 --output.every_time=0.0002", dir_ / "a.log");
  ASSERT_EQ(r.status, 0) << r.output;
  ASSERT_TRUE(fs::exists(dir_ / "out" / "hourglass_block_000020.vtu"));
  r = runProgram("run " + args, dir_ / "b.log");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.output.find("--overwrite"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("already holds the output of a run"), std::string::npos) << r.output;
  r = runProgram("run " + args + " --time.end=0.004 --output.every_time=0.002 --overwrite",
                 dir_ / "c.log");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(fs::exists(dir_ / "out" / "hourglass_block_000002.vtu"));
  EXPECT_FALSE(fs::exists(dir_ / "out" / "hourglass_block_000020.vtu"));  // stale frame removed
}

// A distributed run's frames (NAME_NNNNNN.pvtu and the directory of its pieces) mark the
// directory as holding a run, and --overwrite removes them; other files and directories stay.
TEST_F(CheckpointRestart, FramesInPiecesAreAnEarlierRunsOutput) {
  const fs::path out = dir_ / "pieces";
  fs::create_directories(out / "beam_000001");
  fs::create_directories(out / "beam_00001x");
  std::ofstream(out / "beam_000001" / "beam_000001_0.vtu") << "piece";
  std::ofstream(out / "notes.txt") << "mine";
  std::ofstream(out / "beam_000001.pvtu") << "index";
  EXPECT_EQ(tlsph::runOutputFiles(out, "beam"),
            (std::vector<fs::path>{out / "beam_000001", out / "beam_000001.pvtu"}));
  EXPECT_THROW(tlsph::prepareOutputDirectory(out, "beam", false, false),
               tlsph::OutputDirectoryError);
  EXPECT_TRUE(fs::exists(out / "beam_000001" / "beam_000001_0.vtu"));
  tlsph::prepareOutputDirectory(out, "beam", true, false);
  EXPECT_FALSE(fs::exists(out / "beam_000001"));
  EXPECT_FALSE(fs::exists(out / "beam_000001.pvtu"));
  EXPECT_TRUE(fs::exists(out / "beam_00001x"));
  EXPECT_TRUE(fs::exists(out / "notes.txt"));
}

// The output directory cannot be created: a clear error before anything runs.
TEST_F(CheckpointRestart, UncreatableOutputDirectoryIsRefused) {
  std::ofstream(dir_ / "file") << "in the way";
  const auto r = runProgram("run " + scene("examples/hourglass_block.ini") +
                                " --output.directory=" + (dir_ / "file" / "out").string(),
                            dir_ / "a.log");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.output.find("output directory"), std::string::npos) << r.output;
}

// A write that fails (here: files limited to 24 kB with ulimit -f) stops the run with exit 6,
// a message naming the file, and the earlier complete version of that file left in place.
TEST_F(CheckpointRestart, FailedWriteStopsTheRunAndLeavesCompleteFiles) {
  const fs::path out = dir_ / "out";
  const std::string command = "sh -c 'ulimit -f 24; exec " + std::string(TLSPH_PROGRAM) + " run " +
                              scene("examples/hourglass_block.ini") +
                              " --time.end=0.05 --output.fields=none --output.every_time=0.05"
                              " --output.series_every_steps=1 --output.flush_every_seconds=0"
                              " --output.directory=" +
                              out.string() + "' > " + (dir_ / "log").string() + " 2>&1";
  const int status = WEXITSTATUS(std::system(command.c_str()));
  const std::string log = readFile(dir_ / "log");
  EXPECT_EQ(status, 6) << log;
  EXPECT_NE(log.find("writing the output failed"), std::string::npos) << log;
  EXPECT_NE(log.find("energies.csv"), std::string::npos) << log;
  EXPECT_NE(log.find("checkpoint"), std::string::npos) << log;
  // The file on disk is a complete earlier version: every line whole, the header first.
  std::ifstream csv(out / "energies.csv");
  std::string line;
  int rows = 0;
  bool header = false;
  while (std::getline(csv, line)) {
    if (line.empty() || line[0] == '#') continue;
    if (!header) {
      header = true;
      continue;
    }
    EXPECT_EQ(std::count(line.begin(), line.end(), ','), 13) << line;  // 14 columns
    ++rows;
  }
  EXPECT_TRUE(header);
  EXPECT_GT(rows, 10);
  for (const auto& entry : fs::directory_iterator(out))
    EXPECT_EQ(entry.path().string().find(".tmp-"), std::string::npos) << entry.path();
}

TEST_F(CheckpointRestart, CheckEstimatesTheOutputSize) {
  const auto r = runProgram("check " + scene("examples/hourglass_block.ini"), dir_ / "a.log");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_NE(r.output.find("output size  at most"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("checkpoints  "), std::string::npos) << r.output;
}

}  // namespace
