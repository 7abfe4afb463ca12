// The Ganzenmueller hourglass force (6.80, 6.81): central and antisymmetric pair forces, so it
// conserves linear and angular momentum; zero for every affine deformation and rigid rotation.
#include <gtest/gtest.h>

#include "TestSupport.hpp"

using namespace tlsph;
using namespace tlsph::testing;

namespace {

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

template <int D>
struct HourglassCase {
  std::mt19937 rng;
  double dx = 0.01;
  ForceEvaluator<D> eval;
  explicit HourglassCase(std::uint32_t seed)
      : rng(seed),
        eval(sceneOf<D>(perturbedBlock<D>(counts(), 0.01, 0.2, rng), 0.01, 2.5,
                        testMaterial("neo-hookean"), 10.0)) {}
  static std::array<int, D> counts() {
    std::array<int, D> c;
    c.fill(D == 2 ? 7 : 4);
    return c;
  }
  const std::vector<Vec<D>>& X() const { return eval.scene().particles.referencePosition; }

  // Largest hourglass force magnitude for a given displacement field.
  double largest(const std::vector<Vec<D>>& u) {
    eval.force(u);
    double m = 0.0;
    for (const auto& f : eval.forces().hourglassForce())
      m = std::max(m, f.norm());
    return m;
  }
  std::vector<Vec<D>> noisy(double amplitude) {
    std::vector<Vec<D>> u(eval.size());
    for (auto& ui : u)
      ui = randomVector<D>(rng, amplitude * dx);
    return u;
  }
};

template <int D>
void expectMomentumConservation(std::uint32_t seed) {
  HourglassCase<D> c(seed);
  const Mat<D> A = randomMatrix<D>(c.rng, 0.2);
  auto u = c.noisy(0.05);
  for (Index i = 0; i < c.eval.size(); ++i)
    u[i] += A * c.X()[i];
  c.eval.force(u);
  const auto& fhg = c.eval.forces().hourglassForce();
  const auto x = c.eval.currentPositions(u);
  Vec<D> total = Vec<D>::Zero();
  double scale = 0.0, armScale = 0.0;
  for (Index i = 0; i < c.eval.size(); ++i) {
    total += fhg[i];
    scale += fhg[i].norm();
    armScale += x[i].norm() * fhg[i].norm();
  }
  ASSERT_GT(scale, 0.0);
  EXPECT_LT(total.norm(), 1e-13 * scale);
  EXPECT_LT(torque<D>(x, fhg).norm(), 1e-13 * armScale);
}

template <int D>
void expectVanishesForAffineAndRotation(std::uint32_t seed) {
  HourglassCase<D> c(seed);
  const double reference = c.largest(c.noisy(0.01));  // a non-affine field of similar size
  ASSERT_GT(reference, 0.0);
  for (int trial = 0; trial < 4; ++trial) {
    const Mat<D> A = Mat<D>::Identity() + randomMatrix<D>(c.rng, 0.3);
    const Mat<D> R = randomRotation<D>(c.rng);
    const Vec<D> b = randomVector<D>(c.rng, 0.1);
    std::vector<Vec<D>> affine(c.eval.size()), rotated(c.eval.size());
    for (Index i = 0; i < c.eval.size(); ++i) {
      affine[i] = (A - Mat<D>::Identity()) * c.X()[i] + b;
      rotated[i] = (R - Mat<D>::Identity()) * c.X()[i] + b;
    }
    EXPECT_LT(c.largest(affine), 1e-9 * reference) << "affine trial " << trial;
    EXPECT_LT(c.largest(rotated), 1e-9 * reference) << "rotation trial " << trial;
  }
}

}  // namespace

TEST(Hourglass, ConservesLinearAndAngularMomentum2D) {
  expectMomentumConservation<2>(31);
}
TEST(Hourglass, ConservesLinearAndAngularMomentum3D) {
  expectMomentumConservation<3>(32);
}
TEST(Hourglass, VanishesForAffineDeformationAndRotation2D) {
  expectVanishesForAffineAndRotation<2>(33);
}
TEST(Hourglass, VanishesForAffineDeformationAndRotation3D) {
  expectVanishesForAffineAndRotation<3>(34);
}

TEST(Hourglass, OffMeansNotComputed) {
  std::mt19937 rng(35);
  ForceEvaluator<2> eval(sceneOf<2>(perturbedBlock<2>({5, 5}, 0.01, 0.2, rng), 0.01, 2.5,
                                    testMaterial("linear-elastic"), 0.0));
  EXPECT_FALSE(eval.forces().hourglassEnabled());
  eval.force(std::vector<Vec<2>>(eval.size(), Vec<2>::Zero()));
  EXPECT_TRUE(eval.forces().hourglassForce().empty());
}

TEST(Hourglass, OpposesAZigZagMode) {
  // A checkerboard displacement on a regular lattice is invisible to F in the interior
  // (a zero-energy mode); the penalty force points against it: f . u < 0.
  const double dx = 0.01;
  const auto X = cellCentredLattice<2>(Vec<2>::Zero(), {10, 10}, dx);
  ForceEvaluator<2> eval(sceneOf<2>(X, dx, 2.0, testMaterial("linear-elastic"), 10.0));
  std::vector<Vec<2>> u(eval.size());
  for (Index i = 0; i < eval.size(); ++i) {
    const int ix = static_cast<int>(X[i].x() / dx), iy = static_cast<int>(X[i].y() / dx);
    u[i] = Vec<2>(((ix + iy) % 2 ? 1e-4 : -1e-4) * dx, 0.0);
  }
  eval.force(u);
  double power = 0.0;
  for (Index i = 0; i < eval.size(); ++i)
    power += eval.forces().hourglassForce()[i].dot(u[i]);
  EXPECT_LT(power, 0.0);
}
