#include "modes/HighestFrequency.hpp"

#include <Spectra/SymEigsSolver.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <span>

#include "implicit/DofMap.hpp"
#include "implicit/TangentStiffness.hpp"

namespace tlsph {

namespace {

// y = M^{-1/2} K M^{-1/2} x: symmetric, with the eigenvalues of K phi = lambda M phi.
template <int D>
class ScaledStiffness {
 public:
  using Scalar = double;
  ScaledStiffness(TangentStiffness<D>& K, const Eigen::VectorXd& inverseRootMass)
      : K_(K), s_(inverseRootMass), x_(s_.size()), y_(s_.size()) {}
  Eigen::Index rows() const { return s_.size(); }
  Eigen::Index cols() const { return s_.size(); }
  void perform_op(const double* in, double* out) const {
    x_ = s_.cwiseProduct(Eigen::Map<const Eigen::VectorXd>(in, s_.size()));
    K_.apply(x_, y_);
    Eigen::Map<Eigen::VectorXd>(out, s_.size()) = s_.cwiseProduct(y_);
    ++products;
  }
  mutable int products = 0;

 private:
  TangentStiffness<D>& K_;
  const Eigen::VectorXd& s_;
  mutable Eigen::VectorXd x_, y_;  // Spectra calls a const operator
};

}  // namespace

template <int D>
SpectralEstimate highestFrequency(const Scene<D>& scene, const ReferenceConfiguration<D>& ref,
                                  double relativeTolerance) {
  SpectralEstimate result;
  const auto start = std::chrono::steady_clock::now();
  const auto& hourglass = scene.hourglass();
  if (hourglass.enabled() && hourglass.form != HourglassForm::Energy) {
    result.why = "the textbook hourglass force (6.80)-(6.81) is not the gradient of an energy";
    return result;
  }
  const auto& p = scene.particles;
  const DofMap<D> dofs(p, scene.mirrorGhosts);
  const Index n = D * dofs.size();
  if (n == 0) {
    result.why = "no particle is free to move";
    return result;
  }
  TangentStiffness<D> K(ref, scene.materials, p.material, p.volume, hourglass, dofs,
                        scene.quadrature, p.quadratureMoments());
  const std::vector<Mat<D>> identity(p.size(), Mat<D>::Identity());
  K.update(std::span<const Mat<D>>(identity));  // the reference state, u = 0
  Eigen::VectorXd inverseRootMass(n);
  for (Index d = 0; d < dofs.size(); ++d)
    inverseRootMass.template segment<D>(D * d).setConstant(
        1.0 / std::sqrt(p.mass[dofs.freeParticles()[d]]));

  ScaledStiffness<D> op(K, inverseRootMass);
  if (n == 1) {  // Spectra needs at least two unknowns
    double one = 1.0, out = 0.0;
    op.perform_op(&one, &out);
    result.lambda = out;
    result.particle = dofs.freeParticles()[0];
  } else {
    const Eigen::Index ncv = std::min<Eigen::Index>(n, 24);
    Spectra::SymEigsSolver<ScaledStiffness<D>> eigs(op, 1, ncv);
    // Spectra's start vector is a fixed pseudo-random one: the estimate is reproducible.
    eigs.init();
    eigs.compute(Spectra::SortRule::LargestAlge, 1000, relativeTolerance);
    if (eigs.info() != Spectra::CompInfo::Successful) {
      result.why = "Lanczos did not converge on the largest eigenvalue";
      result.products = op.products;
      return result;
    }
    result.lambda = eigs.eigenvalues()[0];
    const Eigen::VectorXd shape = inverseRootMass.cwiseProduct(eigs.eigenvectors().col(0));
    double largest = -1.0;
    for (Index d = 0; d < dofs.size(); ++d) {
      const double amplitude = shape.template segment<D>(D * d).norm();
      if (amplitude > largest) {
        largest = amplitude;
        result.particle = dofs.freeParticles()[d];
      }
    }
  }
  result.products = op.products;
  result.made = result.lambda > 0.0 && std::isfinite(result.lambda);
  if (!result.made) result.why = "the largest eigenvalue is not positive";
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

template SpectralEstimate highestFrequency<2>(const Scene<2>&, const ReferenceConfiguration<2>&,
                                              double);
template SpectralEstimate highestFrequency<3>(const Scene<3>&, const ReferenceConfiguration<3>&,
                                              double);

}  // namespace tlsph
