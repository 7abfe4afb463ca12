// Smoothing kernels with compact support 2h, evaluated in the reference configuration only
// (a total-Lagrangian code never re-evaluates them during a run).
#pragma once

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "model/Types.hpp"

namespace tlsph {

enum class KernelType { WendlandC2, CubicBSpline };

// The value W(r) and its radial derivative dW/dr of a radially symmetric kernel in D dimensions.
template <int D>
class Kernel {
 public:
  // supportRadius H = 2h: the kernel vanishes for r >= H.
  Kernel(KernelType type, double supportRadius) : type_(type), h_(0.5 * supportRadius) {
    if (!(supportRadius > 0.0) || !std::isfinite(supportRadius))
      throw std::invalid_argument("kernel support radius must be positive and finite, got " +
                                  std::to_string(supportRadius));
    norm_ = normalisation(type, h_);
  }

  KernelType type() const { return type_; }
  double smoothingLength() const { return h_; }
  double supportRadius() const { return 2.0 * h_; }

  double value(double r) const {
    const double q = r / h_;
    if (q >= 2.0) return 0.0;
    switch (type_) {
      case KernelType::WendlandC2: {
        const double s = 1.0 - 0.5 * q;  // (6.14), with the normalised constant
        return norm_ * s * s * s * s * (1.0 + 2.0 * q);
      }
      case KernelType::CubicBSpline:
        if (q < 1.0) return norm_ * (1.0 - 1.5 * q * q + 0.75 * q * q * q);
        return norm_ * 0.25 * (2.0 - q) * (2.0 - q) * (2.0 - q);
    }
    return 0.0;
  }

  // dW/dr
  double derivative(double r) const {
    const double q = r / h_;
    if (q >= 2.0) return 0.0;
    switch (type_) {
      case KernelType::WendlandC2: {
        const double s = 1.0 - 0.5 * q;
        return -5.0 * q * s * s * s * norm_ / h_;
      }
      case KernelType::CubicBSpline:
        if (q < 1.0) return norm_ * (-3.0 * q + 2.25 * q * q) / h_;
        return -0.75 * norm_ * (2.0 - q) * (2.0 - q) / h_;
    }
    return 0.0;
  }

  // gradW_IJ = dW(X_I - X_J)/dX_I for the separation X_IJ = X_I - X_J.
  Vec<D> gradient(const Vec<D>& separation) const {
    const double r = separation.norm();
    if (r == 0.0) return Vec<D>::Zero();
    return (derivative(r) / r) * separation;
  }

 private:
  static double normalisation(KernelType type, double h) {
    constexpr double pi = std::numbers::pi;
    const double hd = D == 2 ? h * h : h * h * h;
    switch (type) {
      case KernelType::WendlandC2:
        return (D == 2 ? 7.0 / (4.0 * pi) : 21.0 / (16.0 * pi)) / hd;
      case KernelType::CubicBSpline:
        return (D == 2 ? 10.0 / (7.0 * pi) : 1.0 / pi) / hd;
    }
    return 0.0;
  }

  KernelType type_;
  double h_;
  double norm_ = 0.0;
};

inline KernelType parseKernelType(std::string_view name) {
  if (name == "wendland-c2") return KernelType::WendlandC2;
  if (name == "cubic-bspline") return KernelType::CubicBSpline;
  throw std::invalid_argument("unknown kernel '" + std::string(name) +
                              "'; expected one of: wendland-c2, cubic-bspline");
}

inline std::string_view kernelName(KernelType type) {
  return type == KernelType::WendlandC2 ? "wendland-c2" : "cubic-bspline";
}

}  // namespace tlsph
