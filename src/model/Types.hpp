// Fixed-size vector and matrix types of a D-dimensional simulation (D = 2: plane strain).
#pragma once

#include <Eigen/Core>

namespace tlsph {

template <int D>
using Vec = Eigen::Matrix<double, D, 1>;

template <int D>
using Mat = Eigen::Matrix<double, D, D>;

using Vec3 = Vec<3>;
using Mat3 = Mat<3>;

using Index = int;  // particle and pair indices; 2^31 particles is far beyond one machine

}  // namespace tlsph
