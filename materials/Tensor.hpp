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

}  // namespace tlsph::tensor
