// A run's checkpoint: everything `tlsph run --restart` needs to continue the run so that its
// result is bit for bit that of the run without the stop (same thread count): the solver's
// state, the Newton solver's load stepping, the guards' memory, and how far each output series
// got. It also records the scene (file text, command-line overrides, and every setting as
// read) and the tlsph version, so that a restart with another scene or another version is
// refused with a message naming the difference.
#pragma once

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "app/Guards.hpp"
#include "explicit/Solver.hpp"
#include "implicit/NewtonSolver.hpp"
#include "io/CheckpointArchive.hpp"
#include "model/QuadratureMoments.hpp"
#include "output/PvdFile.hpp"

namespace tlsph {

// How far the run's output had got when the checkpoint was written.
struct OutputProgress {
  double nextFrameTime = 0.0;
  long lastFrameStep = -1;
  std::uint64_t energyRows = 0, probeRows = 0, reactionRows = 0;
  std::vector<PvdEntry> frames;
};

// What identifies the run a checkpoint belongs to.
struct CheckpointOrigin {
  std::string version;    // tlsph version that wrote it
  std::string sceneFile;  // as given on the command line
  std::string sceneText;  // the scene file's text
  std::vector<std::string> overrides;
  std::vector<std::pair<std::string, std::string>> settings;  // Config::settings()
  int threads = 1;
  // The scene's particles as numbered and placed (particleDigest): a tlsph that numbers or
  // places them otherwise from the same scene (LocalityOrder.hpp) cannot continue the run.
  std::string particles;
};

// "N particles, FNV-1a <hex>" over the bytes of the reference positions in their order, then
// of the particles' quadrature moments when they have their own (a meshed body: a tlsph that
// integrates them otherwise would continue the run with another energy); lattice cells add
// nothing.
template <int D>
std::string particleDigest(const std::vector<Vec<D>>& X, const QuadratureMoments<D>& moments = {}) {
  std::uint64_t h = 14695981039346656037ull;
  auto add = [&h](const double* data, std::size_t count) {
    const auto* b = reinterpret_cast<const unsigned char*>(data);
    for (std::size_t k = 0; k < sizeof(double) * count; ++k)
      h = (h ^ b[k]) * 1099511628211ull;
  };
  for (const auto& x : X)
    add(x.data(), D);
  for (const auto& mu : moments.offset)
    add(mu.data(), D);
  for (const auto& N : moments.spread)
    add(N.data(), D * D);
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h));
  return std::to_string(X.size()) + " particles, FNV-1a " + hex;
}

template <int D>
struct Checkpoint {
  CheckpointOrigin origin;
  SolverState<D> solver;
  GuardState guard;
  std::optional<NewtonState<D>> newton;
  OutputProgress output;
};

namespace checkpoint_detail {

inline std::string joinWithNul(const std::vector<std::string>& items) {
  std::string out;
  for (const auto& s : items) {
    out += s;
    out += '\0';
  }
  return out;
}

inline std::vector<std::string> splitAtNul(const std::string& text) {
  std::vector<std::string> out;
  std::size_t start = 0;
  for (std::size_t k = 0; k < text.size(); ++k)
    if (text[k] == '\0') {
      out.push_back(text.substr(start, k - start));
      start = k + 1;
    }
  return out;
}

// The settings that may differ on a restart, as they do not change the results: when to
// checkpoint, where the output goes (a run's directory may be moved), how often the series
// reach the disk.
inline bool restartMayChange(const std::string& dottedKey) {
  return dottedKey.rfind("checkpoint.", 0) == 0 || dottedKey == "output.directory" ||
         dottedKey == "output.flush_every_seconds";
}

}  // namespace checkpoint_detail

template <int D>
void writeCheckpoint(const std::filesystem::path& file, const Checkpoint<D>& c) {
  using namespace checkpoint_detail;
  CheckpointWriter w;
  w.putString("version", c.origin.version);
  w.put("dimension", static_cast<std::int32_t>(D));
  w.putString("scene_file", c.origin.sceneFile);
  w.putString("scene_text", c.origin.sceneText);
  w.putString("overrides", joinWithNul(c.origin.overrides));
  std::vector<std::string> flat;
  for (const auto& [key, value] : c.origin.settings) {
    flat.push_back(key);
    flat.push_back(value);
  }
  w.putString("settings", joinWithNul(flat));
  w.put("threads", static_cast<std::int32_t>(c.origin.threads));
  w.putString("particles", c.origin.particles);

  const SolverState<D>& s = c.solver;
  w.put("time", s.time);
  w.put("steps", static_cast<std::int64_t>(s.steps));
  w.put("previous_kinetic", s.previousKinetic);
  w.put("kinetic_resets", static_cast<std::int64_t>(s.kineticResets));
  w.put("hourglass_work", s.hourglassWorkDone);
  w.put("external_work", s.externalWork);
  w.put("boundary_work", s.boundaryWork);
  w.put("damped", s.damped);
  w.put("static_books_started", static_cast<std::uint8_t>(s.staticBooksStarted));
  w.putVector("displacement", s.displacement);
  w.putVector("velocity", s.velocity);
  w.putVector("force_velocity", s.forceVelocity);

  w.put("guard", c.guard);

  if (c.newton) {
    const NewtonState<D>& n = *c.newton;
    w.put("newton.done", n.done);
    w.put("newton.increment", n.increment);
    w.put("newton.cuts", static_cast<std::int32_t>(n.cuts));
    w.put("newton.started", static_cast<std::uint8_t>(n.started));
    w.put("newton.factorised", static_cast<std::uint8_t>(n.factorised));
    w.put("newton.last_krylov", static_cast<std::int32_t>(n.lastKrylov));
    w.put("newton.last_step", n.lastStep);
    const NewtonStatistics& st = n.statistics;
    w.putVector("newton.counts",
                std::vector<std::int64_t>{st.loadSteps, st.iterations, st.krylovIterations,
                                          st.factorisations, st.nonZeros, st.factorNonZeros});
    w.putVector("newton.seconds",
                std::vector<double>{st.assemblySeconds, st.factorisationSeconds, st.solveSeconds});
    w.putVector("newton.factor_deformation", n.factorDeformation);
    w.put("newton.levels", static_cast<std::int32_t>(st.levels));
    w.put("newton.factor_time", n.factorTime);
    w.putVector("newton.factor_displacement", n.factorDisplacement);
    w.putVector("newton.factor_second_gradients", n.factorSecondGradients);
  }

  const OutputProgress& o = c.output;
  w.put("output.next_frame_time", o.nextFrameTime);
  w.put("output.last_frame_step", static_cast<std::int64_t>(o.lastFrameStep));
  w.putVector("output.rows", std::vector<std::uint64_t>{o.energyRows, o.probeRows, o.reactionRows});
  std::vector<double> times;
  std::vector<std::string> names;
  for (const auto& f : o.frames) {
    times.push_back(f.time);
    names.push_back(f.file.string());
  }
  w.putVector("output.frame_times", times);
  w.putString("output.frame_files", joinWithNul(names));
  w.write(file);
}

// The identification part only (for a restart's checks before the scene is built).
inline CheckpointOrigin readCheckpointOrigin(const CheckpointReader& r) {
  using namespace checkpoint_detail;
  CheckpointOrigin o;
  o.version = r.getString("version");
  o.sceneFile = r.getString("scene_file");
  o.sceneText = r.getString("scene_text");
  o.overrides = splitAtNul(r.getString("overrides"));
  const auto flat = splitAtNul(r.getString("settings"));
  for (std::size_t k = 0; k + 1 < flat.size(); k += 2)
    o.settings.emplace_back(flat[k], flat[k + 1]);
  o.threads = r.get<std::int32_t>("threads");
  if (r.has("particles")) o.particles = r.getString("particles");
  return o;
}

inline int checkpointDimension(const CheckpointReader& r) {
  return r.get<std::int32_t>("dimension");
}

template <int D>
Checkpoint<D> readCheckpoint(const CheckpointReader& r) {
  using namespace checkpoint_detail;
  if (checkpointDimension(r) != D)
    throw CheckpointError("checkpoint " + r.file().string() + ": written by a " +
                          std::to_string(checkpointDimension(r)) + "D run, this scene is " +
                          std::to_string(D) + "D");
  Checkpoint<D> c;
  c.origin = readCheckpointOrigin(r);
  SolverState<D>& s = c.solver;
  s.time = r.get<double>("time");
  s.steps = r.get<std::int64_t>("steps");
  s.previousKinetic = r.get<double>("previous_kinetic");
  s.kineticResets = r.get<std::int64_t>("kinetic_resets");
  s.hourglassWorkDone = r.get<double>("hourglass_work");
  s.externalWork = r.get<double>("external_work");
  s.boundaryWork = r.get<double>("boundary_work");
  s.damped = r.get<double>("damped");
  s.staticBooksStarted = r.get<std::uint8_t>("static_books_started") != 0;
  s.displacement = r.getVector<Vec<D>>("displacement");
  s.velocity = r.getVector<Vec<D>>("velocity");
  s.forceVelocity = r.getVector<Vec<D>>("force_velocity");
  c.guard = r.get<GuardState>("guard");
  if (r.has("newton.done")) {
    NewtonState<D> n;
    n.done = r.get<double>("newton.done");
    n.increment = r.get<double>("newton.increment");
    n.cuts = r.get<std::int32_t>("newton.cuts");
    n.started = r.get<std::uint8_t>("newton.started") != 0;
    n.factorised = r.get<std::uint8_t>("newton.factorised") != 0;
    n.lastKrylov = r.get<std::int32_t>("newton.last_krylov");
    n.lastStep = r.get<double>("newton.last_step");
    const auto counts = r.getVector<std::int64_t>("newton.counts");
    const auto seconds = r.getVector<double>("newton.seconds");
    if (counts.size() != 6 || seconds.size() != 3)
      throw CheckpointError("checkpoint " + r.file().string() + ": damaged Newton statistics");
    NewtonStatistics& st = n.statistics;
    st.loadSteps = static_cast<int>(counts[0]);
    st.iterations = static_cast<int>(counts[1]);
    st.krylovIterations = counts[2];
    st.factorisations = static_cast<int>(counts[3]);
    st.nonZeros = counts[4];
    st.factorNonZeros = counts[5];
    st.assemblySeconds = seconds[0];
    st.factorisationSeconds = seconds[1];
    st.solveSeconds = seconds[2];
    n.factorDeformation = r.getVector<Mat<D>>("newton.factor_deformation");
    // The multigrid preconditioner's state (absent from checkpoints of earlier versions).
    if (r.has("newton.factor_time")) {
      st.levels = r.get<std::int32_t>("newton.levels");
      n.factorTime = r.get<double>("newton.factor_time");
      n.factorDisplacement = r.getVector<Vec<D>>("newton.factor_displacement");
      n.factorSecondGradients =
          r.getVector<typename TaylorQuadrature<D>::SymMatrix>("newton.factor_second_gradients");
    }
    c.newton = std::move(n);
  }
  OutputProgress& o = c.output;
  o.nextFrameTime = r.get<double>("output.next_frame_time");
  o.lastFrameStep = r.get<std::int64_t>("output.last_frame_step");
  const auto rows = r.getVector<std::uint64_t>("output.rows");
  if (rows.size() != 3)
    throw CheckpointError("checkpoint " + r.file().string() + ": damaged output record");
  o.energyRows = rows[0];
  o.probeRows = rows[1];
  o.reactionRows = rows[2];
  const auto times = r.getVector<double>("output.frame_times");
  const auto names = splitAtNul(r.getString("output.frame_files"));
  if (times.size() != names.size())
    throw CheckpointError("checkpoint " + r.file().string() + ": damaged frame list");
  for (std::size_t k = 0; k < times.size(); ++k)
    o.frames.push_back({times[k], names[k]});
  return c;
}

// Why a checkpoint cannot continue this run ("" if it can): another tlsph version, a scene
// whose settings differ (the first difference is named; [checkpoint] settings may change), or
// particles numbered or placed otherwise (particleDigest).
inline std::string checkpointMismatch(const CheckpointOrigin& saved, const std::string& version,
                                      const std::vector<std::pair<std::string, std::string>>& now,
                                      const std::string& particles) {
  using checkpoint_detail::restartMayChange;
  if (saved.version != version)
    return "it was written by tlsph " + saved.version + ", this is tlsph " + version +
           " (a restart continues a run bit for bit only with the program that began it)";
  std::vector<std::pair<std::string, std::string>> a, b;
  for (const auto& kv : saved.settings)
    if (!restartMayChange(kv.first)) a.push_back(kv);
  for (const auto& kv : now)
    if (!restartMayChange(kv.first)) b.push_back(kv);
  auto section = [](const std::string& dotted) {
    const auto dot = dotted.rfind('.');
    return "[" + dotted.substr(0, dot) + "] " + dotted.substr(dot + 1);
  };
  std::size_t i = 0, j = 0;
  while (i < a.size() || j < b.size()) {
    if (j == b.size() || (i < a.size() && a[i].first < b[j].first))
      return "its scene sets " + section(a[i].first) + " = " + a[i].second +
             ", this scene does not";
    if (i == a.size() || b[j].first < a[i].first)
      return "this scene sets " + section(b[j].first) + " = " + b[j].second +
             ", the checkpoint's scene does not";
    if (a[i].second != b[j].second)
      return "its scene has " + section(a[i].first) + " = " + a[i].second + ", this scene " +
             b[j].second;
    ++i;
    ++j;
  }
  if (saved.particles != particles)
    return saved.particles.empty()
               ? "it does not record its scene's particles (written by an earlier tlsph, which "
                 "may number them otherwise)"
               : "its scene's particles were " + saved.particles + ", this scene's are " +
                     particles + " (numbered or placed otherwise by the tlsph that wrote it)";
  return "";
}

}  // namespace tlsph
