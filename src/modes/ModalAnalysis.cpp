#include "modes/ModalAnalysis.hpp"

#include <Spectra/SymEigsShiftSolver.h>

#include <algorithm>
#include <cmath>
#include <sstream>

#include "explicit/Diagnostics.hpp"
#include "implicit/ConjugateGradients.hpp"
#include "implicit/DofMap.hpp"
#include "implicit/SparseCholesky.hpp"
#include "implicit/TangentStiffness.hpp"

namespace tlsph {

namespace {

// y = M^{1/2} (K - sigma M)^{-1} M^{1/2} x, for Spectra's shift-invert Lanczos.
template <int D>
class ShiftInvert {
 public:
  using Scalar = double;
  ShiftInvert(TangentStiffness<D>& K, const SparseCholesky& factor, const Eigen::VectorXd& mass)
      : K_(K), factor_(factor), mass_(mass), root_(mass.cwiseSqrt()) {}
  Eigen::Index rows() const { return mass_.size(); }
  Eigen::Index cols() const { return mass_.size(); }
  void set_shift(double sigma) { sigma_ = sigma; }
  void perform_op(const double* in, double* out) const {
    const Eigen::VectorXd b = root_.cwiseProduct(Eigen::Map<const Eigen::VectorXd>(in, rows()));
    Eigen::VectorXd y = factor_.solve(b);
    const auto cg = conjugateGradients(
        [&](const Eigen::VectorXd& v, Eigen::VectorXd& Kv) {
          K_.apply(v, Kv);
          Kv -= sigma_ * mass_.cwiseProduct(v);
        },
        [&](const Eigen::VectorXd& r) { return factor_.solve(r); }, b, y, 1e-11 * b.norm(), 1000);
    if (cg.negativeCurvature) notPositive_ = true;
    iterations_ += cg.iterations;
    ++solves_;
    Eigen::Map<Eigen::VectorXd>(out, rows()) = root_.cwiseProduct(y);
  }
  long iterations() const { return iterations_; }
  long solves() const { return solves_; }
  bool notPositive() const { return notPositive_; }

 private:
  TangentStiffness<D>& K_;
  const SparseCholesky& factor_;
  const Eigen::VectorXd& mass_;
  Eigen::VectorXd root_;
  double sigma_ = 0.0;
  mutable long iterations_ = 0, solves_ = 0;
  mutable bool notPositive_ = false;
};

// The hourglass content (Diagnostics.hpp) of the displacement field u.
template <int D>
double hourglassContentOf(const ReferenceConfiguration<D>& ref, const std::vector<double>& volume,
                          const std::vector<Vec<D>>& u) {
  const auto& nb = ref.neighbours;
  std::vector<Mat<D>> H(ref.particleCount(), Mat<D>::Zero());
  for (Index i = 0; i < ref.particleCount(); ++i)
    for (Index k = nb.offset[i]; k < nb.offset[i + 1]; ++k)
      H[i] += (u[nb.neighbour[k]] - u[i]) * ref.correctedGradient[k].transpose();
  return hourglassContent(ref, volume, u, H);
}

}  // namespace

template <int D>
int expectedRigidBodyModes(const Scene<D>& scene) {
  const auto& p = scene.particles;
  for (Index i = 0; i < p.size(); ++i)
    if (p.motion[i] != Motion::Free) return 0;
  const auto& periodic = scene.periodicBox.periodic;
  int count = D;  // translations
  if constexpr (D == 2) {
    if (!scene.periodicBox.any()) ++count;
  } else {
    for (int axis = 0; axis < 3; ++axis) {
      bool free = true;
      for (int other = 0; other < 3; ++other)
        if (other != axis && periodic[other]) free = false;
      count += free;
    }
  }
  return count;
}

template <int D>
ModalResult<D> computeModes(const Scene<D>& scene, Solver<D>& solver,
                            const ModalSettings& settings) {
  const auto& p = scene.particles;
  DofMap<D> dofs(p, scene.mirrorGhosts);
  const Index n = D * dofs.size();
  if (n == 0) throw SetupError("the scene has no free particles: nothing can vibrate");
  TangentStiffness<D> K(solver.reference(), scene.materials, p.material, p.volume,
                        scene.hourglass(), dofs, scene.quadrature);
  K.update(solver.forces().deformationGradient());
  K.updateQuadrature(solver.forces().quadrature(), solver.forces().deformationGradient());
  Eigen::VectorXd mass(n);
  for (Index d = 0; d < dofs.size(); ++d)
    mass.template segment<D>(D * d).setConstant(p.mass[dofs.freeParticles()[d]]);

  ModalResult<D> result;
  result.expectedRigidModes = expectedRigidBodyModes(scene);
  const auto& assembled = K.assemble();
  // The diagonal of the assembled matrix: the first entry of each column (lower triangle).
  for (Eigen::Index c = 0; c < n; ++c) {
    const double diagonal = assembled.valuePtr()[assembled.outerIndexPtr()[c]];
    result.eigenvalueScale = std::max(result.eigenvalueScale, diagonal / mass[c]);
  }
  // Just below zero: K - sigma M is positive definite even with rigid-body modes, and the
  // eigenvalues nearest sigma are the lowest.
  result.shift = -1e-6 * result.eigenvalueScale;
  K.addToDiagonal(-result.shift * mass);
  SparseCholesky factor;
  if (!factor.factorise(assembled))
    throw SetupError(
        "the shifted stiffness K - sigma M is not positive definite: the state is "
        "not stable (buckled or inverted material)");
  result.factorNonZeros = factor.factorNonZeros();
  result.linearSolver = SparseCholesky::name();

  ShiftInvert<D> op(K, factor, mass);
  const Eigen::Index nev = std::min<Eigen::Index>(settings.count, n - 1);
  const Eigen::Index ncv = std::min<Eigen::Index>(n, std::max<Eigen::Index>(2 * nev + 1, 20));
  Spectra::SymEigsShiftSolver<ShiftInvert<D>> eigs(op, nev, ncv, result.shift);
  eigs.init();
  eigs.compute(Spectra::SortRule::LargestMagn, 1000, 1e-10, Spectra::SortRule::SmallestAlge);
  result.krylovIterations = op.iterations();
  result.solves = op.solves();
  if (op.notPositive())
    throw SetupError(
        "the stiffness is not positive definite about this state (buckled or "
        "inverted material): its modes are not vibrations");
  if (eigs.info() != Spectra::CompInfo::Successful) {
    std::ostringstream msg;
    msg << "the eigensolver did not converge for the lowest " << nev << " modes";
    throw SetupError(msg.str());
  }
  const Eigen::VectorXd lambda = eigs.eigenvalues();
  const Eigen::MatrixXd psi = eigs.eigenvectors();
  const double pi = std::acos(-1.0);
  std::vector<Vec<D>> full(p.size());
  for (Eigen::Index m = 0; m < lambda.size(); ++m) {
    Mode<D> mode;
    mode.eigenvalue = lambda[m];
    mode.zero = std::abs(lambda[m]) < settings.zeroThreshold * result.eigenvalueScale;
    mode.frequency = mode.zero ? 0.0 : std::sqrt(std::max(lambda[m], 0.0)) / (2.0 * pi);
    const Eigen::VectorXd phi = psi.col(m).cwiseQuotient(mass.cwiseSqrt());
    Eigen::VectorXd Kphi, Khg;
    K.apply(phi, Kphi);
    K.apply(phi, Khg, TangentStiffness<D>::Part::Penalty);
    const double energy = phi.dot(Kphi);
    mode.penaltyShare = energy > 0.0 && !mode.zero ? phi.dot(Khg) / energy : 0.0;
    dofs.expand(phi, full);
    mode.hourglassContent = hourglassContentOf(solver.reference(), p.volume, full);
    double largest = 0.0;
    for (const auto& u : full)
      largest = std::max(largest, u.norm());
    mode.shape = full;
    if (largest > 0.0)
      for (auto& u : mode.shape)
        u /= largest;
    result.zeroModes += mode.zero;
    result.modes.push_back(std::move(mode));
  }
  return result;
}

template int expectedRigidBodyModes<2>(const Scene<2>&);
template int expectedRigidBodyModes<3>(const Scene<3>&);
template ModalResult<2> computeModes<2>(const Scene<2>&, Solver<2>&, const ModalSettings&);
template ModalResult<3> computeModes<3>(const Scene<3>&, Solver<3>&, const ModalSettings&);

}  // namespace tlsph
