// Artificial viscosity (6.77) in its total-Lagrangian pair form, on the plain loops
// (method/PairForces.hpp): central and antisymmetric pair
// forces (linear and angular momentum conserved), zero for rigid motion and for separating
// pairs, never a source of energy; in a run its work is booked as damping and the books
// balance; off means not computed.
#include <gtest/gtest.h>

#include "TestSupport.hpp"
#include "explicit/Solver.hpp"
#include "method/PairForces.hpp"

using namespace tlsph;
using namespace tlsph::testing;

namespace {

constexpr double kDx = 0.01;

template <int D>
struct ViscousCase {
  std::mt19937 rng;
  Scene<D> scene;
  ReferenceConfiguration<D> ref;
  PairForces<D> forces;
  explicit ViscousCase(std::uint32_t seed, ViscositySettings q = {1.0, 2.0})
      : rng(seed),
        scene(sceneOf<D>(perturbedBlock<D>(counts(), kDx, 0.2, rng), kDx, 2.5,
                         testMaterial("neo-hookean"))),
        ref(buildReferenceConfiguration<D>(scene.particles.referencePosition,
                                           scene.particles.volume,
                                           Kernel<D>(scene.kernel, scene.supportRadius))),
        forces(ref, scene.materials, scene.particles.material, scene.particles.volume,
               HourglassSettings{}, Quadrature::Nodal, q, 0.5 * scene.supportRadius) {}
  static std::array<int, D> counts() {
    std::array<int, D> c;
    c.fill(D == 2 ? 6 : 4);
    return c;
  }
  Index size() const { return scene.particles.size(); }
  const std::vector<Vec<D>>& X() const { return scene.particles.referencePosition; }
  // The viscous force for displacements u and velocities v.
  std::vector<Vec<D>> viscous(const std::vector<Vec<D>>& u, const std::vector<Vec<D>>& v) {
    std::vector<Vec<D>> f(size());
    forces.compute(u, f, &v);
    return forces.viscousForce();
  }
  std::vector<Vec<D>> noisy(double amplitude) {
    std::vector<Vec<D>> w(size());
    for (auto& wi : w)
      wi = randomVector<D>(rng, amplitude);
    return w;
  }
};

template <int D>
void expectConservesMomentaAndDissipates(std::uint32_t seed) {
  ViscousCase<D> c(seed);
  auto u = c.noisy(0.05 * kDx);
  const auto v = c.noisy(1.0);
  const auto f = c.viscous(u, v);
  Vec<D> total = Vec<D>::Zero();
  Vec3 torque = Vec3::Zero();
  double scale = 0.0, armScale = 0.0, power = 0.0;
  for (Index i = 0; i < c.size(); ++i) {
    Vec3 x = Vec3::Zero(), fi = Vec3::Zero();
    x.template head<D>() = c.X()[i] + u[i];
    fi.template head<D>() = f[i];
    total += f[i];
    torque += x.cross(fi);
    scale += f[i].norm();
    armScale += x.norm() * f[i].norm();
    power += f[i].dot(v[i]);
  }
  ASSERT_GT(scale, 0.0);
  EXPECT_LT(total.norm(), 1e-13 * scale);
  EXPECT_LT(torque.norm(), 1e-13 * armScale);
  EXPECT_LT(power, 0.0);  // removes energy
}

template <int D>
void expectZeroForRigidMotionAndSeparation(std::uint32_t seed) {
  ViscousCase<D> c(seed);
  const std::vector<Vec<D>> u(c.size(), Vec<D>::Zero());
  double reference = 0.0;
  for (const auto& f : c.viscous(u, c.noisy(1.0)))
    reference = std::max(reference, f.norm());
  ASSERT_GT(reference, 0.0);
  // rigid: v = b + W x with W skew; expansion: v = x (every pair separates)
  Mat<D> W = randomMatrix<D>(c.rng, 1.0);
  W = 0.5 * (W - W.transpose()).eval();
  const Vec<D> b = randomVector<D>(c.rng, 1.0);
  std::vector<Vec<D>> rigid(c.size()), expanding(c.size());
  for (Index i = 0; i < c.size(); ++i) {
    rigid[i] = b + W * c.X()[i] * 100.0;
    expanding[i] = 100.0 * c.X()[i];
  }
  for (const auto& f : c.viscous(u, rigid))
    EXPECT_LT(f.norm(), 1e-12 * reference);
  for (const auto& f : c.viscous(u, expanding))
    EXPECT_EQ(f.norm(), 0.0);
}

}  // namespace

TEST(ArtificialViscosity, ConservesMomentaAndRemovesEnergy) {
  expectConservesMomentaAndDissipates<2>(71);
  expectConservesMomentaAndDissipates<3>(72);
}

TEST(ArtificialViscosity, ZeroForRigidMotionAndSeparatingPairs) {
  expectZeroForRigidMotionAndSeparation<2>(73);
  expectZeroForRigidMotionAndSeparation<3>(74);
}

TEST(ArtificialViscosity, OffMeansNotComputed) {
  ViscousCase<2> c(75, ViscositySettings{});
  EXPECT_FALSE(c.forces.viscosityEnabled());
  EXPECT_TRUE(c.viscous(c.noisy(0.0), c.noisy(1.0)).empty());
}

// A free block whose two halves collide: the viscosity takes energy out, the books (with its
// work as damping) stay balanced, and the kinetic energy left is lower than without it.
TEST(ArtificialViscosity, ImpactBooksBalanceAndEnergyIsRemoved) {
  auto run = [](ViscositySettings q) {
    const auto X = cellCentredLattice<2>(Vec<2>::Zero(), {20, 6}, kDx);
    Scene<2> scene = sceneOf<2>(X, kDx, 2.1, testMaterial("neo-hookean"), 10.0);
    scene.gradientCorrection = GradientCorrection::Quadratic;
    scene.viscosity = q;
    const double c = waveSpeed(scene.materials[0]);
    for (Index i = 0; i < scene.particles.size(); ++i)
      scene.particles.velocity[i].x() = (X[i].x() < 0.1 ? 0.05 : -0.05) * c;
    Solver<2> solver(scene);
    const double e0 = solver.energyBalance().total();
    double worst = 0.0;
    for (int s = 0; s < 400; ++s) {
      solver.step();
      worst = std::max(worst, std::abs(solver.energyBalance().total() - e0));
    }
    const EnergyBalance e = solver.energyBalance();
    return std::array<double, 3>{worst / e0, e.damped / e0, e.kinetic / e0};
  };
  const auto without = run({});
  const auto with = run({1.0, 2.0});
  std::cout << "impact: books error " << without[0] << " / " << with[0] << ", damped share 0 / "
            << with[1] << ", kinetic share " << without[2] << " / " << with[2]
            << " (without / with viscosity)\n";
  EXPECT_EQ(without[1], 0.0);
  EXPECT_GT(with[1], 0.01);
  EXPECT_LT(with[0], 2e-3);
  EXPECT_LT(with[2], without[2]);
}
