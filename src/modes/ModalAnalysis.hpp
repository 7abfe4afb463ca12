// Natural modes of a scene about its present state (the reference state before a run):
// the lowest eigenpairs of K phi = omega^2 M phi, with K the tangent stiffness on the unknowns
// (TangentStiffness: prescribed particles eliminated, mirrored ghosts chained) and M the free
// particles' lumped masses, found by shift-invert Lanczos (Spectra) on
//   M^{1/2} (K - sigma M)^{-1} M^{1/2},  sigma < 0 just below zero,
// each solve by conjugate gradients on the exact K preconditioned with the Cholesky factor of
// the assembled K - sigma M. For each mode: whether it is a zero-energy mode, the share of its
// energy the hourglass penalty carries, and its hourglass content (how much of the relative
// displacement of neighbours the smooth field 1/2 (F_I + F_J) X_IJ does not explain), which
// finds spurious modes even where boundaries lift them above zero.
#pragma once

#include <string>
#include <vector>

#include "explicit/Solver.hpp"
#include "model/Scene.hpp"

namespace tlsph {

struct ModalSettings {
  int count = 12;                // modes wanted, the lowest
  double zeroThreshold = 1e-10;  // omega^2 below this times the scale counts as zero
};

template <int D>
struct Mode {
  double eigenvalue = 0.0;  // omega^2 [1/s^2]
  double frequency = 0.0;   // omega / (2 pi) [Hz]; 0 for a zero mode
  bool zero = false;
  // phi^T K_hg phi / phi^T K phi (0 without the penalty)
  double penaltyShare = 0.0;
  // sum_IJ W_IJ V_J |e_IJ|^2 / sum_IJ W_IJ V_J |phi_I - phi_J|^2 with
  // e_IJ = phi_I - phi_J - 1/2 (H_I + H_J) X_IJ: 0 for affine (and, with the quadratic
  // correction, quadratic) fields, near 1 for a zig-zag
  double hourglassContent = 0.0;
  std::vector<Vec<D>> shape;  // on every particle, scaled to a largest |u| of 1
};

template <int D>
struct ModalResult {
  std::vector<Mode<D>> modes;  // by increasing eigenvalue
  int zeroModes = 0;
  int expectedRigidModes = 0;    // rigid-body motions the conditions leave free
  double eigenvalueScale = 0.0;  // max over unknowns of K_pp / m_p: about the largest omega^2
  double shift = 0.0;            // sigma
  long krylovIterations = 0;
  long solves = 0;
  long factorNonZeros = 0;
  std::string linearSolver;
};

// Throws SetupError if the eigensolver does not converge or K - sigma M is not positive
// definite.
template <int D>
ModalResult<D> computeModes(const Scene<D>& scene, Solver<D>& solver,
                            const ModalSettings& settings);

// Rigid-body motions left free by the scene's conditions: none when any particle is prescribed
// or mirrored; otherwise the translations, and the rotations about axes that no periodic axis
// other than their own breaks.
template <int D>
int expectedRigidBodyModes(const Scene<D>& scene);

extern template ModalResult<2> computeModes<2>(const Scene<2>&, Solver<2>&, const ModalSettings&);
extern template ModalResult<3> computeModes<3>(const Scene<3>&, Solver<3>&, const ModalSettings&);

}  // namespace tlsph
