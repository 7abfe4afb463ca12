// The rigid motions of a particle set (model/RigidModes.hpp): an orthonormal basis, whose
// projection removes every rigid motion and keeps what is orthogonal to them, a stretch about
// the centroid.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "model/RigidModes.hpp"

using namespace tlsph;

namespace {

template <int D>
std::vector<Vec<D>> scattered(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uniform(-1.0, 2.0);
  std::vector<Vec<D>> X(n);
  for (auto& x : X)
    for (int a = 0; a < D; ++a)
      x[a] = uniform(rng);
  return X;
}

template <int D>
void expectRigidMotionsProjectedAway() {
  const int n = 40;
  const auto X = scattered<D>(n, 7);
  const std::vector<Vec<D>> u(n, Vec<D>::Constant(0.01));  // positions x = X + u
  std::vector<Index> all(n);
  for (int i = 0; i < n; ++i)
    all[i] = i;
  RigidModes<D> rigid;
  rigid.update(all, X, u);
  // A translation plus an infinitesimal rotation about an arbitrary point of the present x.
  const Vec<D> t = Vec<D>::LinSpaced(D, 0.3, -0.7);
  Mat<D> W = Mat<D>::Zero();  // skew
  W(0, 1) = 0.4;
  W(1, 0) = -0.4;
  if constexpr (D == 3) {
    W(0, 2) = -0.2;
    W(2, 0) = 0.2;
    W(1, 2) = 0.9;
    W(2, 1) = -0.9;
  }
  Eigen::VectorXd motion(D * n), stretch(D * n);
  Vec<D> centre = Vec<D>::Zero();
  for (int i = 0; i < n; ++i)
    centre += X[i] + u[i];
  centre /= n;
  for (int i = 0; i < n; ++i) {
    const Vec<D> x = X[i] + u[i];
    motion.template segment<D>(D * i) = t + W * (x - Vec<D>::Constant(5.0));
    stretch.template segment<D>(D * i) = x - centre;
  }
  EXPECT_NEAR(rigid.rigidPart(motion), motion.norm(), 1e-12 * motion.norm());
  rigid.project(motion);
  EXPECT_LT(motion.norm(), 1e-13 * stretch.norm());
  // A uniform stretch about the centroid has no rigid part (its moment about the centroid is
  // zero, its mean is zero): the projection leaves it.
  Eigen::VectorXd kept = stretch;
  rigid.project(kept);
  EXPECT_LT((kept - stretch).norm(), 1e-13 * stretch.norm());
  EXPECT_LT(rigid.rigidPart(stretch), 1e-13 * stretch.norm());
}

}  // namespace

TEST(RigidModes, ProjectionRemovesRigidMotionsAndKeepsAStretch2D) {
  expectRigidMotionsProjectedAway<2>();
}

TEST(RigidModes, ProjectionRemovesRigidMotionsAndKeepsAStretch3D) {
  expectRigidMotionsProjectedAway<3>();
}

TEST(RigidModes, ShiftRaisesOnlyTheDiagonal) {
  Eigen::SparseMatrix<double> K(3, 3);
  K.insert(0, 0) = 2.0;
  K.insert(1, 0) = -1.0;
  K.insert(1, 1) = 2.0;
  K.insert(2, 2) = 4.0;
  const auto S = shiftDiagonal(K);
  EXPECT_DOUBLE_EQ(S.coeff(0, 0), 2.0 * (1.0 + kRigidShift));
  EXPECT_DOUBLE_EQ(S.coeff(2, 2), 4.0 * (1.0 + kRigidShift));
  EXPECT_DOUBLE_EQ(S.coeff(1, 0), -1.0);
}
