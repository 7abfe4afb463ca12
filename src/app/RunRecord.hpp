// summary.json: what a run was and what it cost, for scripts (the validation runner) to read
// without parsing the console. Written atomically next to the run's other output.
#pragma once

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "app/RunSimulation.hpp"
#include "io/AtomicFile.hpp"
#include "io/JsonText.hpp"
#include "io/RoundTripNumber.hpp"

namespace tlsph {

inline const char* outcomeName(RunOutcome o) {
  switch (o) {
    case RunOutcome::Finished:
      return "finished";
    case RunOutcome::Converged:
      return "converged";
    case RunOutcome::NotConverged:
      return "not-converged";
    case RunOutcome::Unstable:
      return "unstable";
    case RunOutcome::Interrupted:
      return "interrupted";
    case RunOutcome::OutputFailed:
      return "output-failed";
  }
  return "";
}

template <int D>
void writeRunRecord(const std::filesystem::path& file, const SceneSetup<D>& setup,
                    const NeighbourStats& nb, const RunSummary& s, int threads,
                    const std::string& command, const std::string& version) {
  Index ghosts = 0;
  for (auto g : setup.ghost)
    ghosts += g;
  const Index n = setup.scene.particles.size();
  std::ostringstream j;
  auto field = [&](const char* key, const std::string& value, bool last = false) {
    j << "  " << jsonText(key) << ": " << value << (last ? "\n" : ",\n");
  };
  j << "{\n";
  field("tlsph_version", jsonText(version));
  field("scene", jsonText(setup.name));
  field("source", jsonText(setup.sourceFile));
  field("command", jsonText(command));
  field("dimension", std::to_string(D));
  field("particles", std::to_string(n));
  field("ghost_particles", std::to_string(ghosts));
  field("dx", jsonNumber(setup.dx));
  field("support_over_dx", jsonNumber(setup.scene.supportRadius / setup.dx));
  field("kernel", jsonText(std::string(kernelName(setup.scene.kernel))));
  field("gradient_correction", jsonText(gradientCorrectionName(setup.scene.gradientCorrection)));
  field("quadrature", jsonText(quadratureName(setup.scene.quadrature)));
  field("hourglass_alpha", jsonNumber(setup.scene.hourglassCoefficient));
  field("hourglass_form", jsonText(hourglassFormName(setup.scene.hourglassForm)));
  field("hourglass_gradient", jsonText(hourglassGradientName(setup.scene.hourglassGradient)));
  field("viscosity_linear", jsonNumber(setup.scene.viscosity.linear));
  field("viscosity_quadratic", jsonNumber(setup.scene.viscosity.quadratic));
  field("neighbours_min", std::to_string(nb.min));
  field("neighbours_mean", jsonNumber(nb.mean));
  field("neighbours_max", std::to_string(nb.max));
  field("cfl", jsonNumber(setup.solver.cfl));
  field("dt", jsonNumber(s.timeStep));
  // The step rule dt = cfl dx / sqrt(c^2 + c_hg^2) at the limiting particle (also when
  // [time] dt overrides it): the predicted critical step is dt_rule / cfl times the measured
  // critical C (about 0.5 with the quadratic correction, validation/report/stability.md).
  field("dt_rule", jsonNumber(s.stableStep.dt));
  field("dt_rule_particle", std::to_string(s.stableStep.particle));
  field("dt_rule_wave_speed", jsonNumber(s.stableStep.waveSpeed));
  field("dt_rule_hourglass_speed", jsonNumber(s.stableStep.hourglassSpeed));
  field("dt_rule_limited_by",
        jsonText(s.stableStep.hourglassSpeed > s.stableStep.waveSpeed ? "hourglass penalty"
                                                                      : "material wave speed"));
  // The operator's cap (velocity Verlet's linear limit 2 / omega_max times 0.8), null when
  // none was estimated; dt_spectral_binds: the run's step is the cap.
  const SpectralStep& cap = s.spectralStep;
  field("omega_max", cap.made ? jsonNumber(std::sqrt(cap.lambda)) : "null");
  field("dt_spectral_limit", cap.made ? jsonNumber(cap.limit) : "null");
  field("dt_spectral_particle", cap.made ? std::to_string(cap.particle) : "null");
  field("dt_spectral_binds", cap.binds ? "true" : "false");
  field("steps", std::to_string(s.steps));
  field("simulated_time", jsonNumber(s.time));
  field("wall_seconds", jsonNumber(s.wallSeconds));
  // threads: OpenMP threads per rank; ranks: MPI processes (1 for a serial run).
  field("threads", std::to_string(threads));
  field("ranks", std::to_string(s.partition.ranks));
  field("partition_method", jsonText(s.partition.method));
  field("halo_particles", std::to_string(s.partition.halo));
  field("partition_imbalance", jsonNumber(s.partition.imbalance));
  field("particle_steps_per_second",
        jsonNumber(s.wallSeconds > 0 ? double(n) * s.steps / s.wallSeconds : 0.0));
  field("outcome", jsonText(outcomeName(s.outcome)));
  field("residual", jsonNumber(s.residual));
  field("energy_kinetic", jsonNumber(s.energy.kinetic));
  field("energy_strain", jsonNumber(s.energy.strain));
  field("energy_hourglass", jsonNumber(s.energy.hourglass));
  field("external_work", jsonNumber(s.energy.externalWork));
  field("damped", jsonNumber(s.energy.damped));
  field("pvd", jsonText(s.pvd.string()));
  // Checkpoint/restart: the last checkpoint this run wrote, and where a restarted run began.
  field("checkpoint", jsonText(s.checkpoint.string()));
  field("restarted_at_step", s.restartedAtStep >= 0 ? std::to_string(s.restartedAtStep) : "null");
  field("energies", jsonText(s.energies.string()));
  if (s.instability) {
    // What the stability guard found (app/Guards.hpp).
    const Instability& u = *s.instability;
    auto vec = [](const std::vector<double>& v) {
      std::string out = "[";
      for (std::size_t a = 0; a < v.size(); ++a) {
        if (a) out += ", ";
        out += jsonNumber(v[a]);
      }
      return out + "]";
    };
    std::ostringstream o;
    o << "{\"step\": " << u.step << ", \"time\": " << jsonNumber(u.time)
      << ", \"quantity\": " << jsonText(u.quantity) << ", \"value\": " << jsonNumber(u.value)
      << ", \"description\": " << jsonText(u.description)
      << ", \"particle\": " << (u.particle >= 0 ? std::to_string(u.particle) : "null")
      << ", \"reference_position\": " << vec(u.referencePosition)
      << ", \"current_position\": " << vec(u.currentPosition)
      << ", \"cause\": " << jsonText(u.cause) << ", \"last_good_step\": " << u.lastGoodStep
      << ", \"last_good_frame\": " << jsonText(u.lastGoodFrame.string())
      << ", \"failed_frame\": " << jsonText(u.failedFrame.string()) << "}";
    field("instability", o.str());
  }
  field(
      "static_solver",
      jsonText(setup.run.quasiStatic ? (setup.run.newtonStatic() ? "newton" : "damped") : "none"));
  if (s.newton) {
    // What the Newton static solve did and where its time went.
    const NewtonStatistics& n = *s.newton;
    std::ostringstream o;
    o << "{\"load_steps\": " << n.loadSteps << ", \"iterations\": " << n.iterations
      << ", \"krylov_iterations\": " << n.krylovIterations
      << ", \"factorisations\": " << n.factorisations << ", \"matrix_nonzeros\": " << n.nonZeros
      << ", \"factor_nonzeros\": " << n.factorNonZeros << ", \"levels\": " << n.levels
      << ", \"assembly_seconds\": " << jsonNumber(n.assemblySeconds)
      << ", \"factorisation_seconds\": " << jsonNumber(n.factorisationSeconds)
      << ", \"solve_seconds\": " << jsonNumber(n.solveSeconds)
      << ", \"linear_solver\": " << jsonText(n.linearSolver) << "}";
    field("newton", o.str());
  }
  field("probes", jsonText(s.probes.string()));
  field("reactions_series", jsonText(s.reactions.string()));
  {
    // The force each clamp and prescription exerts on the body at the end [N; 2D: N/m].
    std::ostringstream o;
    o << "{";
    for (std::size_t r = 0; r < s.finalReactions.size(); ++r) {
      const auto& [name, R] = s.finalReactions[r];
      o << (r ? ", " : "") << jsonText(name) << ": [";
      for (int a = 0; a < D; ++a)
        o << (a ? ", " : "") << jsonNumber(R[a]);
      o << "]";
    }
    o << "}";
    field("reactions", o.str());
  }
  {
    std::ostringstream o;
    o << "[";
    for (std::size_t k = 0; k < setup.warnings.size(); ++k)
      o << (k ? ", " : "") << jsonText(setup.warnings[k]);
    o << "]";
    field("warnings", o.str(), true);
  }
  j << "}\n";
  writeAtomically(file, [&](const std::filesystem::path& tmp) {
    std::ofstream out(tmp);
    out << j.str();
    if (!out.flush()) throw std::runtime_error("cannot write " + tmp.string());
  });
}

}  // namespace tlsph
