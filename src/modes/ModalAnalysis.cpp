#include "modes/ModalAnalysis.hpp"

#include <Spectra/SymEigsShiftSolver.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <numeric>
#include <optional>
#include <random>
#include <sstream>

#include "explicit/Diagnostics.hpp"
#include "implicit/ConjugateGradients.hpp"
#include "implicit/DofMap.hpp"
#include "implicit/SparseCholesky.hpp"
#include "implicit/TangentStiffness.hpp"
#include "method/DeformationGradient.hpp"
#include "modes/ExactStiffness.hpp"
#include "modes/Inertia.hpp"

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
  // Orthonormal directions (in the space of M^{1/2} phi) the operator is to leave out: the
  // modes found by earlier runs. P A P with P = 1 - Q Q^T maps them to 0, far from the
  // eigenvalues 1 / (lambda - sigma) sought, and leaves the others as they are.
  void deflate(const Eigen::MatrixXd* Q) { deflated_ = Q; }
  void perform_op(const double* in, double* out) const {
    Eigen::VectorXd x = Eigen::Map<const Eigen::VectorXd>(in, rows());
    project(x);
    const Eigen::VectorXd b = root_.cwiseProduct(x);
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
    Eigen::VectorXd result = root_.cwiseProduct(y);
    project(result);
    Eigen::Map<Eigen::VectorXd>(out, rows()) = result;
  }
  void project(Eigen::VectorXd& x) const {
    if (deflated_ && deflated_->cols() > 0) x -= *deflated_ * (deflated_->transpose() * x);
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
  const Eigen::MatrixXd* deflated_ = nullptr;
  mutable long iterations_ = 0, solves_ = 0;
  mutable bool notPositive_ = false;
};

// The hourglass content (Diagnostics.hpp) of the displacement field u.
template <int D>
double hourglassContentOf(const ReferenceConfiguration<D>& ref, const std::vector<double>& volume,
                          const std::vector<Vec<D>>& u) {
  const auto& nb = ref.neighbours;
  std::vector<Mat<D>> H(ref.particleCount());
  for (Index i = 0; i < ref.particleCount(); ++i)
    H[i] = displacementGradientAt<D>(nb, ref.correctedGradient, u, i);
  return hourglassContent(ref, volume, u, H);
}

// One Lanczos run for the `nev` lowest eigenpairs of the operator deflated of `Q`; returns the
// converged ones (eigenvalues, and the eigenvectors in the M^{1/2} phi space as columns).
template <int D>
std::pair<Eigen::VectorXd, Eigen::MatrixXd> lanczos(ShiftInvert<D>& op, const Eigen::MatrixXd& Q,
                                                    Eigen::Index nev, double shift, int round) {
  const Eigen::Index n = op.rows();
  const Eigen::Index free = n - Q.cols();
  nev = std::min(nev, free - 1);
  if (nev < 1) return {};
  const Eigen::Index ncv = std::min(free, std::max<Eigen::Index>(2 * nev + 1, 20));
  op.deflate(&Q);
  Spectra::SymEigsShiftSolver<ShiftInvert<D>> eigs(op, nev, ncv, shift);
  // another start vector each run: the first run's would again see the missed direction weakly
  std::mt19937_64 random(1234567 + round);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  Eigen::VectorXd start(n);
  for (Eigen::Index i = 0; i < n; ++i)
    start[i] = uniform(random);
  op.project(start);
  eigs.init(start.data());
  eigs.compute(Spectra::SortRule::LargestMagn, 1000, 1e-10, Spectra::SortRule::SmallestAlge);
  op.deflate(nullptr);
  return {eigs.eigenvalues(), eigs.eigenvectors()};
}

// The cut in omega^2 of a band edge at f Hz: eigenvalues below it are below f. 0 Hz takes the
// zero modes in (the cut below them), a positive edge below sigma_0 leaves them out.
double bandCut(double hz, double zeroShift) {
  const double pi = std::acos(-1.0);
  if (hz == 0.0) return -zeroShift;
  return std::max(std::pow(2.0 * pi * hz, 2), zeroShift);
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
                        scene.hourglass(), dofs, scene.quadrature, p.quadratureMoments());
  K.update(solver.forces().deformationGradient());
  K.updateQuadrature(solver.forces().quadrature(), solver.forces().deformationGradient());
  Eigen::VectorXd mass(n);
  for (Index d = 0; d < dofs.size(); ++d)
    mass.template segment<D>(D * d).setConstant(p.mass[dofs.freeParticles()[d]]);

  ModalResult<D> result;
  result.expectedRigidModes = expectedRigidBodyModes(scene);

  // The exact K and its inertia, before the assembled matrix is shifted below.
  InertiaCheck& check = result.inertia;
  std::optional<Inertia> inertia;
  {
    const auto start = std::chrono::steady_clock::now();
    const ExactStiffness exact = exactStiffness(K, solver.reference(), dofs,
                                                scene.hourglass().enabled(), settings.maxNonZeros);
    check.exactK = exact.method;
    check.probes = exact.products;
    check.groups = exact.groups;
    check.kNonZeros = exact.nonZeros;
    check.mismatch = exact.productMismatch;
    check.kSeconds = exact.seconds;
    if (exact.made) {
      inertia.emplace(exact.lower, mass);
      check.factorNonZeros = inertia->factorNonZeros();
      if (check.factorNonZeros > settings.maxNonZeros) {
        std::ostringstream why;
        why << "its L D L^T factor would hold " << check.factorNonZeros
            << " entries, above the limit of " << settings.maxNonZeros;
        check.why = why.str();
        inertia.reset();
      }
    } else {
      check.why = exact.reason;
    }
    check.made = inertia.has_value();
    check.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  std::map<double, long> counted;  // a shift asked for again is not factorised again
  auto countBelow = [&](double sigma) {
    if (const auto known = counted.find(sigma); known != counted.end()) return known->second;
    const auto start = std::chrono::steady_clock::now();
    long below = inertia->countBelow(sigma);
    // an exactly zero pivot: sigma on an eigenvalue; a shift off it by far less than the gaps
    // the callers keep counts the same
    for (int tries = 0; below < 0 && tries < 4; ++tries)
      below = inertia->countBelow(sigma + 1e-9 * (std::abs(sigma) + result.zeroShift));
    if (below < 0) throw SetupError("the L D L^T factorisation of K - sigma M broke down");
    check.factorisations = inertia->factorisations();
    check.seconds +=
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    counted[sigma] = below;
    return below;
  };

  const auto& assembled = K.assemble();
  // The diagonal of the assembled matrix: the first entry of each column (lower triangle).
  for (Eigen::Index c = 0; c < n; ++c) {
    const double diagonal = assembled.valuePtr()[assembled.outerIndexPtr()[c]];
    result.eigenvalueScale = std::max(result.eigenvalueScale, diagonal / mass[c]);
  }
  result.zeroShift = settings.zeroShift * result.eigenvalueScale;
  long wanted = settings.count;
  if (settings.band) {
    result.bandLow = bandCut(settings.lowHz, result.zeroShift);
    result.bandHigh = bandCut(settings.highHz, result.zeroShift);
    if (settings.highHz == 0.0) result.bandHigh = result.zeroShift;
    if (inertia) {
      wanted = countBelow(result.bandHigh);
    } else {
      wanted = 12;  // then doubled until a mode above the band is found
    }
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

  // Lanczos runs until the modes found below the cut are all there are (by inertia).
  ShiftInvert<D> op(K, factor, mass);
  Eigen::VectorXd lambda(0);
  Eigen::MatrixXd psi(n, 0);
  Eigen::Index nev = std::min<Eigen::Index>(std::max<long>(wanted, 1), n - 1);
  for (int round = 0; round < settings.maxRounds && nev > 0; ++round) {
    const auto [values, vectors] = lanczos(op, psi, nev, result.shift, round);
    ++result.rounds;
    if (op.notPositive())
      throw SetupError(
          "the stiffness is not positive definite about this state (buckled or "
          "inverted material): its modes are not vibrations");
    if (values.size() == 0 && round == 0) {
      std::ostringstream msg;
      msg << "the eigensolver did not converge for the lowest " << nev << " modes";
      throw SetupError(msg.str());
    }
    // merged by increasing eigenvalue; the new vectors made orthogonal to the old ones (they
    // are, to the accuracy of the run)
    Eigen::VectorXd allValues(lambda.size() + values.size());
    Eigen::MatrixXd allVectors(n, lambda.size() + values.size());
    allValues << lambda, values;
    allVectors << psi, vectors;
    for (Eigen::Index c = psi.cols(); c < allVectors.cols(); ++c) {
      for (Eigen::Index k = 0; k < c; ++k)
        allVectors.col(c) -= allVectors.col(k).dot(allVectors.col(c)) * allVectors.col(k);
      allVectors.col(c).normalize();
    }
    std::vector<Eigen::Index> order(allValues.size());
    std::iota(order.begin(), order.end(), 0);
    std::sort(order.begin(), order.end(),
              [&](Eigen::Index a, Eigen::Index b) { return allValues[a] < allValues[b]; });
    lambda.resize(allValues.size());
    psi.resize(n, allValues.size());
    for (std::size_t k = 0; k < order.size(); ++k) {
      lambda[k] = allValues[order[k]];
      psi.col(k) = allVectors.col(order[k]);
    }
    nev = 0;
    if (!inertia) {
      // no count to check against: one run, or with a band until a mode above it is found
      if (settings.band && lambda.size() > 0 && lambda[lambda.size() - 1] < result.bandHigh &&
          lambda.size() < n - 1)
        nev = std::min<Eigen::Index>(lambda.size(), n - 1 - lambda.size());
      continue;
    }
    // The cut: the band's upper edge, or just above the highest mode to be listed (sigma_0
    // when that is a zero mode, so that the whole null space is found), with a relative gap
    // well above the modes' accuracy (1e-10) and the factorisation's rounding.
    if (settings.band) {
      check.cut = result.bandHigh;
    } else {
      const Eigen::Index top = std::min<Eigen::Index>(wanted, lambda.size()) - 1;
      check.cut = lambda[top] < result.zeroShift ? result.zeroShift
                                                 : lambda[top] + 1e-4 * std::abs(lambda[top]);
    }
    check.below = countBelow(check.cut);
    check.found = (lambda.array() < check.cut).count();
    check.complete = check.below == check.found && lambda.size() >= std::min<long>(wanted, n - 1);
    if (check.complete || check.below < check.found) break;
    // the missing ones are the lowest the deflated operator has: ask for them and a few more
    nev = std::min<Eigen::Index>(check.below - check.found + 2, n - 1 - lambda.size());
    if (lambda.size() < wanted) nev = std::max<Eigen::Index>(nev, wanted - lambda.size());
  }
  result.krylovIterations = op.iterations();
  result.solves = op.solves();
  if (inertia && !check.complete) {
    std::ostringstream msg;
    msg << "the modes found are not all the eigenvalues below omega^2 = " << check.cut
        << ": the inertia of K - s M counts " << check.below << " below it, " << result.rounds
        << " Lanczos run(s) found " << check.found
        << "; the list would not be the lowest modes, so none is given";
    throw IncompleteModes(msg.str());
  }

  // Once the modes found below the cut are all the eigenvalues below it (by inertia), the counts
  // below any lower shift are those of the modes found: the zero modes below sigma_0 <= cut and
  // the band's lower edge need no factorisation of their own.
  if (inertia) {
    result.zeroModes = static_cast<int>((lambda.array() < result.zeroShift).count());
    result.zeroModesByInertia = true;
    if (settings.band) result.inBand = wanted - (lambda.array() < result.bandLow).count();
  }
  // The modes listed: the lowest `count`, or those in the band.
  std::vector<Eigen::Index> listed;
  for (Eigen::Index m = 0; m < lambda.size(); ++m)
    if (settings.band ? lambda[m] >= result.bandLow && lambda[m] < result.bandHigh
                      : m < settings.count)
      listed.push_back(m);
  if (!inertia) {
    for (Eigen::Index m = 0; m < lambda.size(); ++m)
      result.zeroModes += lambda[m] < result.zeroShift;
  }
  const double pi = std::acos(-1.0);
  std::vector<Vec<D>> full(p.size());
  for (Eigen::Index m : listed) {
    Mode<D> mode;
    mode.eigenvalue = lambda[m];
    // by the count: the zero modes are the lowest (when the list is complete, exactly those
    // below sigma_0)
    mode.zero = inertia ? m < result.zeroModes : lambda[m] < result.zeroShift;
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
    result.modes.push_back(std::move(mode));
  }
  return result;
}

template int expectedRigidBodyModes<2>(const Scene<2>&);
template int expectedRigidBodyModes<3>(const Scene<3>&);
template ModalResult<2> computeModes<2>(const Scene<2>&, Solver<2>&, const ModalSettings&);
template ModalResult<3> computeModes<3>(const Scene<3>&, Solver<3>&, const ModalSettings&);

}  // namespace tlsph
