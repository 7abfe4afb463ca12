// The explicit step's cap from the operator's highest frequency (method/TimeStep.hpp
// spectralStepLimit; modes/HighestFrequency.hpp), estimated once at set-up at the reference
// state, so a restarted run gets the step it had. Distributed: rank 0 builds the whole body's
// pair data, estimates, and every rank takes its numbers.
#pragma once

#include <vector>

#include "distributed/Communicator.hpp"
#include "explicit/Solver.hpp"
#include "method/TimeStep.hpp"
#include "modes/HighestFrequency.hpp"
#include "scene/SceneSetup.hpp"

namespace tlsph {

template <int D>
SpectralEstimate estimateSpectralStep(const Scene<D>& scene, const Solver<D>& solver) {
  Communicator* comm = solver.communicator();
  if (!comm) return highestFrequency(scene, solver.reference());
  SpectralEstimate f;
  std::vector<double> numbers(5, 0.0);
  if (comm->rank() == 0) {
    const auto whole = buildSceneReference<D>(
        scene.particles.referencePosition, scene.particles.volume,
        Kernel<D>(scene.kernel, scene.supportRadius), scene.periodicBox, scene.gradientCorrection,
        scene.quadrature, scene.particles.quadratureMoments(), scene.particles.boundaryArea,
        scene.particles.boundaryMoment, scene.integrationFilter);
    f = highestFrequency(scene, whole);
    numbers = {f.made ? 1.0 : 0.0, f.lambda, double(f.particle), double(f.products), f.seconds};
  }
  comm->broadcast(numbers);
  comm->broadcast(f.why);
  f.made = numbers[0] != 0.0;
  f.lambda = numbers[1];
  f.particle = Index(numbers[2]);
  f.products = int(numbers[3]);
  f.seconds = numbers[4];
  return f;
}

// What a run or a check applies: nothing for a Newton static run (no time step) or with
// [time] spectral_limit = false.
template <int D>
void applySpectralStep(const SceneSetup<D>& setup, Solver<D>& solver) {
  if (setup.run.newtonStatic() || !setup.solver.spectralLimit) return;
  solver.limitTimeStep(estimateSpectralStep(setup.scene, solver));
}

}  // namespace tlsph
