// What `tlsph check` prints, and `tlsph run` before its first step: the set-up as built
// (particles, neighbours, materials, conditions, time step and what sets it, output and its
// size), and the warnings only the solver's set-up can give.
#pragma once

#include <cmath>
#include <filesystem>
#include <iostream>
#include <sstream>
#include <string>

#include "app/OutputDirectory.hpp"
#include "explicit/Solver.hpp"
#include "scene/SceneSetup.hpp"

namespace tlsph {

template <int D>
void printSetup(const SceneSetup<D>& setup, const Solver<D>& solver) {
  const auto& p = setup.scene.particles;
  const NeighbourStats nb = solver.neighbourStats();
  Index ghosts = 0;
  for (Index i = 0; i < p.size(); ++i)
    ghosts += setup.ghost[i];
  std::cout << "scene        " << setup.name << " (" << D << "D" << (D == 2 ? ", plane strain" : "")
            << ") from " << setup.sourceFile << "\n"
            << "particles    " << p.size() << " (" << p.size() - ghosts << " body, " << ghosts
            << " ghost), dx = " << setup.dx << " m\n"
            << "neighbours   min " << nb.min << ", mean " << nb.mean << ", max " << nb.max
            << " (kernel " << kernelName(setup.scene.kernel)
            << ", H = " << setup.scene.supportRadius
            << " m = " << setup.scene.supportRadius / setup.dx << " dx, "
            << gradientCorrectionName(setup.scene.gradientCorrection) << " gradient correction, "
            << (setup.scene.quadrature == Quadrature::Taylor ? "Taylor-corrected" : "nodal")
            << " quadrature)\n";
  if (const auto& ic = solver.integrationConstraint(); ic.applied && !ic.linear)
    std::cout << "integration  gradient vectors corrected for the boundary's area vectors: defect "
              << ic.defectBefore << " -> " << ic.defectAfter << " of the largest a_I ("
              << ic.iterations << " CG iterations, "
              << (ic.factorised ? "Cholesky-preconditioned" : "Jacobi-preconditioned") << ", "
              << ic.seconds << " s)\n";
  else if (ic.applied)
    std::cout << "integration  gradient vectors corrected for the boundary's area vectors and "
                 "first moments (linear stress, filter "
              << ic.filter << "): defect " << ic.defectBefore << " -> " << ic.defectAfter
              << " of the largest a_I, first moments " << ic.momentDefectBefore << " -> "
              << ic.momentDefectAfter << " of V_I; correction |delta|/|g| " << ic.correction << " ("
              << ic.iterations << " CG iterations, " << ic.seconds << " s)\n";
  std::cout << "hourglass    alpha = " << setup.scene.hourglassCoefficient
            << (setup.scene.hourglassCoefficient == 0
                    ? std::string(" (off)")
                    : std::string(", form ") + hourglassFormName(setup.scene.hourglassForm) +
                          (setup.scene.hourglassForm == HourglassForm::Energy
                               ? std::string(", on the ") +
                                     hourglassGradientName(setup.scene.hourglassGradient) + " F"
                               : std::string()))
            << "\n";
  if (setup.scene.viscosity.enabled())
    std::cout << "viscosity    artificial (6.77): linear q1 = " << setup.scene.viscosity.linear
              << ", quadratic q2 = " << setup.scene.viscosity.quadratic << "\n";
  for (std::size_t m = 0; m < setup.scene.materials.size(); ++m) {
    const auto& mat = setup.scene.materials[m];
    const auto& c = elasticConstants(mat);
    std::cout << "material     " << setup.materialNames[m] << ": " << materialName(mat)
              << ", rho0 = " << density(mat) << ", E = " << c.youngsModulus
              << ", nu = " << c.poissonRatio << ", wave speed " << waveSpeed(mat) << " m/s\n";
  }
  for (const auto& line : setup.conditions)
    std::cout << "condition    " << line << "\n";
  if (setup.scene.damping.any())
    std::cout << "damping      viscous " << setup.scene.damping.viscous << " 1/s, kinetic "
              << (setup.scene.damping.kinetic ? "on" : "off") << "\n";
  for (const auto& probe : setup.probes) {
    std::cout << "probe        " << probe.name << " at (" << probe.point.transpose() << "), ";
    if (probe.method == ProbeMethod::Nearest)
      std::cout << "nearest particle\n";
    else if (probe.method == ProbeMethod::Kernel)
      std::cout << "kernel-interpolated, first order\n";
    else
      std::cout << "particle " << probe.particles[0] << " of surface " << probe.surfaceName
                << ", stress recovered from the surface (" << probe.stencil->neighbours.size()
                << " particles) and its traction\n";
  }
  if (setup.run.newtonStatic()) {
    const double end = solver.rampEnd();
    std::cout << "static       Newton-Raphson, " << setup.run.newton.loadSteps
              << " load step(s) to the end of the ramps (t = " << end
              << " s), stop when residual < " << setup.run.tolerance << "; preconditioner "
              << newtonPreconditionerName(setup.run.newton.preconditioner);
    if (setup.run.newton.preconditioner == NewtonPreconditioner::Auto)
      std::cout << " (multigrid from " << setup.run.newton.autoMultigridUnknowns
                << " unknowns unless a Poisson ratio >= " << setup.run.newton.autoPoissonLimit
                << ", else cholesky)";
    std::cout << "\n";
  }
  const double steps = setup.run.endTime / solver.timeStep();
  std::cout << "time         dt = " << solver.timeStep() << " s (CFL " << setup.solver.cfl
            << "), end " << setup.run.endTime << " s, " << (setup.run.quasiStatic ? "at most " : "")
            << static_cast<long>(std::ceil(steps)) << " steps"
            << (setup.run.quasiStatic
                    ? ", static: stop when residual < " + std::to_string(setup.run.tolerance)
                    : std::string())
            << "\n";
  {
    // What sets the step: dt = C_cfl dx / sqrt(c^2 + c_hg^2) at the limiting particle.
    const StableStep& rule = solver.stableStepRule();
    const Vec<D> X = p.referencePosition[rule.particle];
    std::cout << "time step    "
              << (setup.solver.timeStep > 0.0 ? "[time] dt given; the rule gives " : "rule: ")
              << rule.dt << " s = CFL x dx / c_eff at particle " << rule.particle << " ("
              << X.transpose() << "): dx = " << rule.dx
              << " m, material wave speed c = " << rule.waveSpeed << " m/s";
    if (rule.hourglassSpeed > 0.0)
      std::cout << ", hourglass springs add c_hg = " << rule.hourglassSpeed
                << " m/s (c_eff = " << rule.hourglassFactor() << " c)";
    std::cout << "; limited by the "
              << (rule.hourglassSpeed > rule.waveSpeed ? "hourglass penalty"
                                                       : "material wave speed")
              << "\n";
    // The operator's cap: 0.8 x 2 / omega_max (method/TimeStep.hpp).
    const SpectralStep& cap = solver.spectralStep();
    if (cap.made) {
      const Vec<D> Y = p.referencePosition[cap.particle];
      std::cout << "spectrum     omega_max = " << std::sqrt(cap.lambda) << " rad/s (Lanczos, "
                << cap.products << " products K v), largest at particle " << cap.particle << " ("
                << Y.transpose() << "); cap 0.8 x 2 / omega_max = " << cap.limit << " s"
                << (cap.binds ? ": it sets the step (the operator is stiffer than the rule "
                                "predicts)"
                              : " (the rule's step is below it)")
                << "\n";
    } else if (!cap.why.empty()) {
      std::cout << "spectrum     no cap on the step: " << cap.why << "\n";
    }
  }
  std::cout << "output       " << setup.output.directory << "/";
  if (setup.output.fields.empty()) {
    std::cout << " (CSV only)\n";
  } else {
    std::cout << setup.name << ".pvd with";
    for (const auto& f : setup.output.fields)
      std::cout << " " << f;
    std::cout << "\n";
  }
  const OutputEstimate e = estimateOutput(setup, solver.timeStep());
  std::cout << "output size  at most " << byteText(e.total()) << ": " << e.frames << " frames of "
            << byteText(e.frameBytes) << " (uncompressed), " << e.seriesRows << " series rows ("
            << byteText(e.seriesBytes) << "), " << e.checkpointsKept << " checkpoint(s) of "
            << byteText(e.checkpointBytes) << " kept";
  std::error_code noSpace;
  std::filesystem::path existing = setup.output.directory;
  while (!existing.empty() && !std::filesystem::exists(existing, noSpace))
    existing = existing.parent_path();
  const auto space =
      std::filesystem::space(existing.empty() ? std::filesystem::path(".") : existing, noSpace);
  if (!noSpace) std::cout << "; " << byteText(double(space.available)) << " free there";
  std::cout << "\n";
  const CheckpointSettings& ck = setup.checkpoint;
  std::cout << "checkpoints  ";
  if (ck.everySteps > 0)
    std::cout << "every " << ck.everySteps << (setup.run.newtonStatic() ? " load" : "")
              << " steps, ";
  if (ck.everySeconds > 0) std::cout << "every " << ck.everySeconds << " s of wall time, ";
  std::cout << "on SIGINT/SIGTERM and on a failed write; the newest " << ck.keep << " kept in "
            << setup.output.directory << "/checkpoints/\n";
}

// Warnings only the solver's set-up can give (added to the scene's, for summary.json).
template <int D>
void addSolverWarnings(SceneSetup<D>& setup, const Solver<D>& solver, const std::string& command) {
  const FallbackSummary& fallback = solver.linearFallback();
  if (fallback.count == 0) return;
  const Index i = fallback.first;
  std::ostringstream w;
  w << setup.sourceFile << ": [kernel] correction: " << fallback.count << " of "
    << setup.scene.particles.size() << " particles (e.g. particle " << i << " at ("
    << setup.scene.particles.referencePosition[i].transpose() << ") with " << fallback.neighbours
    << " neighbours) have too few neighbours on two levels for the quadratic correction's fit "
       "(an acute corner, a strip two particles thick); they use the linear correction (6.69), "
       "exact for affine fields only. Raise [kernel] support (2.3 serves Cook's membrane) to "
       "use the quadratic one everywhere";
  setup.warnings.push_back(w.str());
  std::cerr << command << ": warning: " << w.str() << "\n";
}

}  // namespace tlsph
