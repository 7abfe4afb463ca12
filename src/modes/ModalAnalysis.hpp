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
//
// Lanczos from one start vector can miss an eigenvalue of a (near-)degenerate cluster: the
// Krylov space holds one direction per eigenspace but for rounding. So the modes found are
// checked against the inertia of K - s M (Inertia.hpp, on the exact sparse K of
// ExactStiffness.hpp): the count of eigenvalues below a cut s just above the highest mode
// reported must equal the count found below it; while it is larger, Lanczos runs again on the
// operator deflated of the modes found (which makes the missing ones the lowest it sees). The
// zero modes are counted the same way, below a small positive shift sigma_0, not by
// thresholding the modes found.
#pragma once

#include <string>
#include <vector>

#include "explicit/Solver.hpp"
#include "model/Scene.hpp"

namespace tlsph {

struct ModalSettings {
  int count = 12;  // modes wanted, the lowest (without a band)
  // A band instead: every mode with a frequency in [lowHz, highHz] (the zero modes are in it
  // when lowHz is 0).
  bool band = false;
  double lowHz = 0.0, highHz = 0.0;
  // sigma_0 = zeroShift x the eigenvalue scale: the eigenvalues below it are the zero modes
  double zeroShift = 1e-10;
  // The exact sparse K and its L D L^T factor each at most this many entries (12 bytes each):
  // beyond it no inertia count is made (the zero modes are then counted by thresholding the
  // modes found at sigma_0 and the list is not checked).
  long maxNonZeros = 200'000'000;
  int maxRounds = 8;  // Lanczos runs, each deflating the modes found before
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

// The inertia check: counts of eigenvalues below shifts, from L D L^T of K - s M.
struct InertiaCheck {
  bool made = false;        // the exact K and its factor fit ModalSettings::maxNonZeros
  std::string why;          // when not made: why
  std::string exactK;       // "assembled" or "probed"
  long probes = 0;          // K v products of the probing
  int groups = 0;           // its groups of unknowns
  long kNonZeros = 0;       // entries of the exact K (lower triangle)
  double mismatch = 0.0;    // |K_sparse v - K v| / |K v|, random v
  long factorNonZeros = 0;  // entries of L D L^T
  long factorisations = 0;
  double kSeconds = 0.0;  // making the exact K
  double seconds = 0.0;   // making K and factorising
  // The cut just above the highest mode reported (or the band's upper edge): the eigenvalues
  // below it by inertia and among the modes found.
  double cut = 0.0;
  long below = -1, found = 0;
  bool complete = false;  // below == found: no mode below the cut is missing
};

template <int D>
struct ModalResult {
  std::vector<Mode<D>> modes;  // by increasing eigenvalue
  // Zero modes: by inertia, the eigenvalues below sigma_0 (all of them, also when fewer modes
  // are listed); without it, the modes found below sigma_0.
  int zeroModes = 0;
  bool zeroModesByInertia = false;
  int expectedRigidModes = 0;    // rigid-body motions the conditions leave free
  double eigenvalueScale = 0.0;  // max over unknowns of K_pp / m_p: about the largest omega^2
  double zeroShift = 0.0;        // sigma_0 [1/s^2]
  double shift = 0.0;            // sigma
  long inBand = -1;              // with a band: its eigenvalues by inertia (-1: not counted)
  double bandLow = 0.0, bandHigh = 0.0;  // the band as cuts in omega^2
  InertiaCheck inertia;
  int rounds = 0;  // Lanczos runs
  long krylovIterations = 0;
  long solves = 0;
  long factorNonZeros = 0;
  std::string linearSolver;
};

// The modes found could not be shown complete: the inertia counts more eigenvalues below the
// cut than the Lanczos runs found (or fewer: a spurious Ritz value). tlsph modes exits with 7.
struct IncompleteModes : SetupError {
  using SetupError::SetupError;
};

// Throws SetupError if the eigensolver does not converge or K - sigma M is not positive
// definite, IncompleteModes if the list cannot be checked complete.
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
