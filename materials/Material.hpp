// The closed set of material models, name lookup, and the D-dimensional entry points
// (D = 2 is plane strain) that the TLSPH loops call.
#pragma once

#include <Eigen/Core>
#include <concepts>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

#include "materials/ElasticConstants.hpp"
#include "materials/LinearElastic.hpp"
#include "materials/MooneyRivlin.hpp"
#include "materials/NeoHookean.hpp"
#include "materials/SaintVenantKirchhoff.hpp"

namespace tlsph {

// What the solver needs from a model; every alternative of Material satisfies it.
//
// tangentModulus(F) is A = dP/dF = d2 psi / dF dF as a 9x9 matrix: F(i, j) and P(i, j) are
// flattened in Eigen's column-major storage order, (i, j) -> i + 3 j, and
// A(a, b) = dP_a / dF_b, so vec(dP) = A vec(dF) with vec(M) = Map<Matrix<double, 9, 1>>(M.data()).
// A is major-symmetric (A = A^T, hyperelastic). Where the model is undefined (det F <= 0) it
// is quiet NaN, like the stress.
template <class M>
concept MaterialModel = requires(const M& m, const Eigen::Matrix3d& F) {
  { m.strainEnergyDensity(F) } -> std::same_as<double>;
  { m.firstPiolaKirchhoff(F) } -> std::same_as<Eigen::Matrix3d>;
  { m.tangentModulus(F) } -> std::same_as<Eigen::Matrix<double, 9, 9>>;
  { m.constants() } -> std::same_as<const ElasticConstants&>;
  { m.density() } -> std::same_as<double>;
  { m.waveSpeed() } -> std::same_as<double>;
  { M::name } -> std::convertible_to<std::string_view>;
  { M::objective } -> std::convertible_to<bool>;
};

// A scene holds one Material per material id; the loops std::visit once per material
// group, so the stress call inside a loop is a direct, inlinable call.
using Material = std::variant<LinearElastic, SaintVenantKirchhoff, NeoHookean, MooneyRivlin>;

inline const ElasticConstants& elasticConstants(const Material& material) {
  return std::visit([](const auto& m) -> const ElasticConstants& { return m.constants(); },
                    material);
}
inline double density(const Material& material) {
  return std::visit([](const auto& m) { return m.density(); }, material);
}
inline double waveSpeed(const Material& material) {
  return std::visit([](const auto& m) { return m.waveSpeed(); }, material);
}
inline std::string_view materialName(const Material& material) {
  return std::visit([](const auto& m) { return std::string_view(m.name); }, material);
}

namespace detail {
template <std::size_t... I>
std::vector<std::string_view> materialNames(std::index_sequence<I...>) {
  return {std::string_view(std::variant_alternative_t<I, Material>::name)...};
}
}  // namespace detail

// The names makeMaterial accepts, in the order of the Material alternatives.
inline std::vector<std::string_view> materialNames() {
  return detail::materialNames(std::make_index_sequence<std::variant_size_v<Material>>());
}

// The model called `name`, built with its default options (Mooney-Rivlin: c01Fraction 0.5).
// Throws MaterialError for an unknown name (listing the valid ones) or an invalid density.
inline Material makeMaterial(std::string_view name, const ElasticConstants& c, double density) {
  std::optional<Material> made;
  [&]<std::size_t... I>(std::index_sequence<I...>) {
    ((name == std::variant_alternative_t<I, Material>::name
          ? void(made.emplace(std::in_place_index<I>, c, density))
          : void()),
     ...);
  }
  (std::make_index_sequence<std::variant_size_v<Material>>());
  if (made) return *std::move(made);
  std::string valid;
  for (const auto n : materialNames())
    valid += (valid.empty() ? "" : ", ") + std::string(n);
  throw MaterialError("unknown material model '" + std::string(name) +
                      "'; valid material names are: " + valid);
}

// ---- Plane strain (D = 2) and 3D entry points ------------------------------------------
// In 2D the in-plane F is embedded with F33 = 1 (no out-of-plane stretch) and the in-plane
// block of the 3D P is returned: it is exactly d psi / d F_2x2 of the embedded energy.
// For D = 3 these are the model's own functions, called directly.

template <int D>
Eigen::Matrix3d embedDeformationGradient(const Eigen::Matrix<double, D, D>& F) {
  static_assert(D == 2 || D == 3, "TLSPH runs in 2D (plane strain) or 3D");
  if constexpr (D == 3) {
    return F;
  } else {
    Eigen::Matrix3d F3 = Eigen::Matrix3d::Identity();
    F3.topLeftCorner<2, 2>() = F;
    return F3;
  }
}

template <int D, MaterialModel Model>
Eigen::Matrix<double, D, D> firstPiolaKirchhoff(const Model& model,
                                                const Eigen::Matrix<double, D, D>& F) {
  static_assert(D == 2 || D == 3, "TLSPH runs in 2D (plane strain) or 3D");
  if constexpr (D == 3)
    return model.firstPiolaKirchhoff(F);
  else
    return model.firstPiolaKirchhoff(embedDeformationGradient<2>(F)).template topLeftCorner<2, 2>();
}

// A = dP/dF with the convention of MaterialModel, in D dimensions: index i + D j. In plane
// strain (D = 2) this is the in-plane block of the 3D tangent at the embedded F: rows and
// columns at the 3D indices i + 3 j with i, j < 2, i.e. {0, 1, 3, 4}, mapped to i + 2 j.
template <int D, MaterialModel Model>
Eigen::Matrix<double, D * D, D * D> tangentModulus(const Model& model,
                                                   const Eigen::Matrix<double, D, D>& F) {
  static_assert(D == 2 || D == 3, "TLSPH runs in 2D (plane strain) or 3D");
  if constexpr (D == 3) {
    return model.tangentModulus(F);
  } else {
    const Eigen::Matrix<double, 9, 9> A3 = model.tangentModulus(embedDeformationGradient<2>(F));
    constexpr int inPlane[4] = {0, 1, 3, 4};
    Eigen::Matrix4d A;
    for (int b = 0; b < 4; ++b)
      for (int a = 0; a < 4; ++a)
        A(a, b) = A3(inPlane[a], inPlane[b]);
    return A;
  }
}

template <int D, MaterialModel Model>
double strainEnergyDensity(const Model& model, const Eigen::Matrix<double, D, D>& F) {
  static_assert(D == 2 || D == 3, "TLSPH runs in 2D (plane strain) or 3D");
  if constexpr (D == 3)
    return model.strainEnergyDensity(F);
  else
    return model.strainEnergyDensity(embedDeformationGradient<2>(F));
}

// Convenience overloads on the variant (one dispatch per call: not for the hot loops,
// which visit once per material group and call the Model overloads above).
template <int D>
Eigen::Matrix<double, D, D> firstPiolaKirchhoff(const Material& material,
                                                const Eigen::Matrix<double, D, D>& F) {
  return std::visit([&](const auto& m) { return firstPiolaKirchhoff<D>(m, F); }, material);
}

template <int D>
double strainEnergyDensity(const Material& material, const Eigen::Matrix<double, D, D>& F) {
  return std::visit([&](const auto& m) { return strainEnergyDensity<D>(m, F); }, material);
}

template <int D>
Eigen::Matrix<double, D * D, D * D> tangentModulus(const Material& material,
                                                   const Eigen::Matrix<double, D, D>& F) {
  return std::visit([&](const auto& m) { return tangentModulus<D>(m, F); }, material);
}

static_assert(MaterialModel<LinearElastic> && MaterialModel<SaintVenantKirchhoff> &&
              MaterialModel<NeoHookean> && MaterialModel<MooneyRivlin>);

}  // namespace tlsph
