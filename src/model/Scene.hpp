// What is simulated: particles, their materials and the discretisation choices.
#pragma once

#include <vector>

#include "materials/Material.hpp"
#include "method/Kernel.hpp"
#include "method/ReferenceConfiguration.hpp"
#include "model/Conditions.hpp"
#include "model/PairTerms.hpp"
#include "model/Particles.hpp"
#include "model/PeriodicBox.hpp"
#include "model/Types.hpp"

namespace tlsph {

template <int D>
struct Scene {
  ParticleSet<D> particles;
  std::vector<Material> materials;
  KernelType kernel = KernelType::WendlandC2;
  double supportRadius = 0.0;  // H = 2h
  GradientCorrection gradientCorrection = GradientCorrection::Linear;
  Quadrature quadrature = Quadrature::Nodal;  // [kernel] quadrature
  double hourglassCoefficient = 0.0;          // alpha of (6.80); 0: no hourglass pass at all
  HourglassForm hourglassForm = HourglassForm::Energy;
  HourglassGradient hourglassGradient = HourglassGradient::Corrected;
  ViscositySettings viscosity;  // artificial viscosity (6.77); off by default
  // The linear-stress constraint's filter ([kernel] integration_filter); 0: that constraint is
  // off (method/IntegrationConstraint.hpp).
  double integrationFilter = 0.0;
  PeriodicBox<D> periodicBox;
  Vec<D> gravity = Vec<D>::Zero();  // body force per unit mass
  Ramp gravityRamp;
  std::vector<Prescription<D>> prescriptions;  // their particles must have Motion::Prescribed
  std::vector<MirrorGhost> mirrorGhosts;       // their ghosts must have Motion::Mirrored
  std::vector<Load<D>> loads;
  Damping damping;

  HourglassSettings hourglass() const {
    return {hourglassCoefficient, hourglassForm, hourglassGradient};
  }
};

}  // namespace tlsph
