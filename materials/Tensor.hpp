// Small 3x3 tensor helpers shared by the material models.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <limits>

namespace tlsph::tensor {

// cof(F) = det(F) F^{-T}. Its columns are cross products of the columns of F, so
// F^T cof(F) = det(F) 1; it gives J = F.col(0) . cof.col(0) and F^{-T} = cof / J
// without a second determinant or a general inverse.
inline Eigen::Matrix3d cofactor(const Eigen::Matrix3d& F) {
  Eigen::Matrix3d cof;
  cof.col(0) = F.col(1).cross(F.col(2));
  cof.col(1) = F.col(2).cross(F.col(0));
  cof.col(2) = F.col(0).cross(F.col(1));
  return cof;
}

inline double determinantFromCofactor(const Eigen::Matrix3d& F, const Eigen::Matrix3d& cof) {
  return F.col(0).dot(cof.col(0));
}

// What a model returns where it is undefined (det F <= 0): the solver's finiteness
// guard turns it into a clear "unstable" report instead of an exception inside a loop.
inline double undefinedEnergy() {
  return std::numeric_limits<double>::quiet_NaN();
}
inline Eigen::Matrix3d undefinedStress() {
  return Eigen::Matrix3d::Constant(std::numeric_limits<double>::quiet_NaN());
}

// ---- Tangent moduli A = dP/dF (see Material.hpp for the convention) -----------------------
// A 3x3 matrix M is flattened in Eigen's storage order, M(i, j) -> index i + 3 j, and
// A(a, b) = dP_a / dF_b. The linear maps dF -> dP that the models need are built from:
//   X dF Y             -> A(i+3j, k+3l) = X(i,k) Y(l,j)   (Y^T kron X)
//   X dF^T Y           -> A(i+3j, l+3k) = X(i,k) Y(l,j)
//   M (N : dF)         -> A = vec(M) vec(N)^T
using Tangent = Eigen::Matrix<double, 9, 9>;
using Vector9d = Eigen::Matrix<double, 9, 1>;

inline Vector9d vec(const Eigen::Matrix3d& M) {
  return Eigen::Map<const Vector9d>(M.data());
}

// A += s * d(X dF Y)/dF: block (j, l) of A is s Y(l, j) X.
inline void addLeftRight(Tangent& A, double s, const Eigen::Matrix3d& X, const Eigen::Matrix3d& Y) {
  for (int j = 0; j < 3; ++j)
    for (int l = 0; l < 3; ++l)
      A.block<3, 3>(3 * j, 3 * l) += (s * Y(l, j)) * X;
}

// A += s * d(X dF^T Y)/dF: block (j, k) of A is s X.col(k) Y.col(j)^T.
inline void addLeftTransposedRight(Tangent& A, double s, const Eigen::Matrix3d& X,
                                   const Eigen::Matrix3d& Y) {
  for (int j = 0; j < 3; ++j)
    for (int k = 0; k < 3; ++k)
      A.block<3, 3>(3 * j, 3 * k).noalias() += (s * X.col(k)) * Y.col(j).transpose();
}

inline Tangent undefinedTangent() {
  return Tangent::Constant(std::numeric_limits<double>::quiet_NaN());
}

}  // namespace tlsph::tensor
