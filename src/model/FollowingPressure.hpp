// A following pressure (docs/method.md section 3.4): a pressure that acts on the current,
// deformed surface, normal to it and over its current area. Per linear facet e (a segment in
// 2D, a triangle in 3D) with current corners x = X + u, the force is -p n_e A_e, shared equally
// among the facet's D corners (int lambda_I n dA of a flat facet):
//   2D: n A = J (x_2 - x_1),  J = [[0, 1], [-1, 0]] (a quarter turn clockwise),
//   3D: n A = 1/2 (x_2 - x_1) x (x_3 - x_1),
// with the corners ordered so that n points out of the body. Its tangent, the derivative of
// the force with respect to the corners' displacements, sits beside it: it is not symmetric
// in general (a pressure on an open surface is not conservative).
#pragma once

#include <array>
#include <utility>
#include <vector>

#include "model/Types.hpp"

namespace tlsph {

template <int D>
class FollowingPressure {
 public:
  FollowingPressure() = default;
  FollowingPressure(std::vector<std::array<Index, D>> facets, double pressure)
      : facets_(std::move(facets)), pressure_(pressure) {}

  const std::vector<std::array<Index, D>>& facets() const { return facets_; }
  double pressure() const { return pressure_; }

  // The area vector n A of facet e at positions X + u.
  Vec<D> areaVector(const std::array<Index, D>& e, const std::vector<Vec<D>>& X,
                    const std::vector<Vec<D>>& u) const {
    const Vec<D> a = (X[e[1]] + u[e[1]]) - (X[e[0]] + u[e[0]]);
    if constexpr (D == 2) {
      return Vec<D>(a.y(), -a.x());
    } else {
      const Vec<D> b = (X[e[2]] + u[e[2]]) - (X[e[0]] + u[e[0]]);
      return Vec<D>(0.5 * a.cross(b));
    }
  }

  // f_I += scale * (-p / D) sum over the facets of I of n_e A_e, at positions X + u.
  void addForce(const std::vector<Vec<D>>& X, const std::vector<Vec<D>>& u, double scale,
                std::vector<Vec<D>>& f) const {
    const double share = -scale * pressure_ / D;
    for (const auto& e : facets_) {
      const Vec<D> fe = share * areaVector(e, X, u);
      for (Index i : e)
        f[i] += fe;
    }
  }

  // The load's stiffness on a variation v (one vector per particle): out_I += -(df_I/du) v, the
  // sign of a stiffness (K = -dr/du). The variation of a facet's area vector,
  //   2D: d(n A) = J (v_2 - v_1),
  //   3D: d(n A) = 1/2 (dx_12 x x_13 + x_12 x dx_13)
  //              = 1/2 sum_a (x_c - x_b) x v_a over the cyclic corners (a, b, c),
  // is linear in v, so this is the exact product with the tangent.
  void addStiffnessProduct(const std::vector<Vec<D>>& X, const std::vector<Vec<D>>& u, double scale,
                           const std::vector<Vec<D>>& v, std::vector<Vec<D>>& out) const {
    const double share = scale * pressure_ / D;
    for (const auto& e : facets_) {
      Vec<D> d;
      if constexpr (D == 2) {
        const Vec<D> dv = v[e[1]] - v[e[0]];
        d = Vec<D>(dv.y(), -dv.x());
      } else {
        const Vec<D> a = (X[e[1]] + u[e[1]]) - (X[e[0]] + u[e[0]]);
        const Vec<D> b = (X[e[2]] + u[e[2]]) - (X[e[0]] + u[e[0]]);
        d = 0.5 * ((v[e[1]] - v[e[0]]).cross(b) + a.cross(v[e[2]] - v[e[0]]));
      }
      d *= share;
      for (Index i : e)
        out[i] += d;
    }
  }

 private:
  std::vector<std::array<Index, D>> facets_;
  double pressure_ = 0.0;
};

}  // namespace tlsph
