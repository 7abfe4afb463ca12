// The plain reference evaluation (method/PairForces.hpp) of a scene through TestSupport's
// ForceEvaluator: the method's tests pin the physics on the plain loops.
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include "TestSupport.hpp"
#include "method/PairForces.hpp"

namespace tlsph::testing {

template <int D>
using PlainEvaluator = ForceEvaluator<D, PairForces<D>>;

// sum_I x_I x f_I (the z component in 2D).
template <int D>
Vec3 torque(const std::vector<Vec<D>>& x, const std::vector<Vec<D>>& f) {
  Vec3 sum = Vec3::Zero();
  for (std::size_t i = 0; i < x.size(); ++i) {
    Vec3 xi = Vec3::Zero(), fi = Vec3::Zero();
    xi.template head<D>() = x[i];
    fi.template head<D>() = f[i];
    sum += xi.cross(fi);
  }
  return sum;
}

// Largest |f - (-dE/du)| over the particles and components, dE/du by central differences of
// step h; fmax (out) the largest |f| component.
template <int D, class Evaluator>
double energyGradientError(Evaluator& eval, std::vector<Vec<D>> u, double h, double& fmax) {
  const auto f = eval.force(u);
  fmax = 0.0;
  for (const auto& fi : f)
    fmax = std::max(fmax, fi.cwiseAbs().maxCoeff());
  double worst = 0.0;
  for (Index i = 0; i < eval.size(); ++i)
    for (int a = 0; a < D; ++a) {
      const double saved = u[i][a];
      u[i][a] = saved + h;
      const double plus = eval.energy(u);
      u[i][a] = saved - h;
      const double minus = eval.energy(u);
      u[i][a] = saved;
      worst = worseOf(worst, std::abs(-(plus - minus) / (2 * h) - f[i][a]));
    }
  return worst;
}

}  // namespace tlsph::testing
