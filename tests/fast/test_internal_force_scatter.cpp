// The force pass summed from its sources (InternalForceScatter): the same products of
// the same values in the same order as the gather, so the forces are the gather's bit for bit,
// with any volumes, ghosts, materials and number of threads; and the pass is used exactly when
// the internal force is the force pass's only pair term.
#include <gtest/gtest.h>

#include <cstring>
#include <random>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "TestSupport.hpp"
#include "fast/TlsphForces.hpp"

using namespace tlsph;
using namespace tlsph::testing;

namespace {

struct ForceSetup {
  Quadrature quadrature = Quadrature::Nodal;
  GradientCorrection correction = GradientCorrection::Linear;
  HourglassSettings hourglass;
  const char* material = "neo-hookean";
  bool ghosts = false;  // passive particles (mirrored ghosts) in the first layer
};

template <int D>
struct Case {
  std::vector<Vec<D>> X, u;
  std::vector<double> V;
  std::vector<Material> materials;
  std::vector<std::uint16_t> materialOf;
  std::vector<Index> passive;
  ReferenceConfiguration<D> ref;
};

// A lattice with volumes varied by up to 20 % (so that t_IJ = (V_J / V_I) g_JI is not g_JI) and
// a smooth displacement with noise.
template <int D>
Case<D> makeCase(const ForceSetup& s) {
  const double dx = 0.01;
  std::array<int, D> counts;
  counts.fill(6);
  counts[0] = 14;
  Case<D> c;
  c.X = cellCentredLattice<D>(Vec<D>::Zero(), counts, dx);
  const Index n = static_cast<Index>(c.X.size());
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> scale(0.9, 1.1);
  for (Index i = 0; i < n; ++i)
    c.V.push_back(std::pow(dx, D) * scale(rng));
  c.materials = {testMaterial(s.material)};
  c.materialOf.assign(n, 0);
  if (s.ghosts)
    for (Index i = 0; i < n; ++i)
      if (c.X[i].x() < dx) c.passive.push_back(i);
  c.ref = buildReferenceConfiguration<D>(c.X, c.V, Kernel<D>(KernelType::WendlandC2, 2.1 * dx), {},
                                         s.correction);
  for (Index i = 0; i < n; ++i)
    c.u.push_back(0.2 * c.X[i].cwiseProduct(c.X[i]) + randomVector<D>(rng, 0.01 * dx));
  return c;
}

template <int D>
std::vector<Vec<D>> forces(const Case<D>& c, const ForceSetup& s, bool scatter, int threads,
                           bool* scattered = nullptr) {
#ifdef _OPENMP
  const int before = omp_get_max_threads();
  omp_set_num_threads(threads);
#else
  (void)threads;
#endif
  TlsphForces<D> forces(c.ref, c.materials, c.materialOf, c.V, s.hourglass, s.quadrature, {}, 0.0,
                        c.passive);
  forces.scatterInternalForce(scatter);
  if (scattered) *scattered = forces.scattersInternalForce();
  std::vector<Vec<D>> f(c.X.size());
  forces.compute(c.u, f);
#ifdef _OPENMP
  omp_set_num_threads(before);
#endif
  return f;
}

template <int D>
void expectBitwiseEqual(const std::vector<Vec<D>>& a, const std::vector<Vec<D>>& b,
                        const std::string& what) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i)
    ASSERT_EQ(std::memcmp(a[i].data(), b[i].data(), sizeof(Vec<D>)), 0)
        << what << ", particle " << i << ": " << a[i].transpose() << " vs " << b[i].transpose();
}

template <int D>
void expectScatterIsGather(const ForceSetup& s) {
  const Case<D> c = makeCase<D>(s);
  bool scattered = false;
  const auto gathered = forces<D>(c, s, false, 1);
  const auto summed = forces<D>(c, s, true, 1, &scattered);
  ASSERT_TRUE(scattered);
  const std::string what = std::to_string(D) + "D, " + s.material +
                           (s.quadrature == Quadrature::Taylor ? ", taylor" : ", nodal") +
                           (s.hourglass.enabled() ? ", penalty" : "") +
                           (s.ghosts ? ", ghosts" : "");
  expectBitwiseEqual<D>(gathered, summed, what);
  // a force that is not trivially zero, and the same bits on other thread counts (each thread's
  // range of targets ends inside other threads' sources' lists)
  double largest = 0.0;
  for (const auto& f : summed)
    largest = std::max(largest, f.norm());
  EXPECT_GT(largest, 0.0) << what;
  for (int threads : {2, 3, 7})
    expectBitwiseEqual<D>(gathered, forces<D>(c, s, true, threads),
                          what + ", " + std::to_string(threads) + " threads");
}

const HourglassSettings kEnergy{10.0, HourglassForm::Energy, HourglassGradient::Corrected};

}  // namespace

TEST(InternalForceScatter, ForcesAreTheGathersBitForBit) {
  for (const char* material : {"neo-hookean", "linear-elastic"})
    for (bool ghosts : {false, true})
      for (const HourglassSettings& hourglass : {HourglassSettings{}, kEnergy}) {
        const ForceSetup taylor{Quadrature::Taylor, GradientCorrection::Quadratic, hourglass,
                                material, ghosts};
        const ForceSetup nodal{Quadrature::Nodal, GradientCorrection::Linear, hourglass, material,
                               ghosts};
        const ForceSetup quadraticNodal{Quadrature::Nodal, GradientCorrection::Quadratic, hourglass,
                                        material, ghosts};
        expectScatterIsGather<2>(taylor);
        expectScatterIsGather<3>(taylor);
        expectScatterIsGather<2>(nodal);
        expectScatterIsGather<3>(nodal);
        expectScatterIsGather<3>(quadraticNodal);
      }
}

// With another pair term in the force pass (the textbook hourglass force, the penalty on its
// own linear F, artificial viscosity) the pass stays a gather.
TEST(InternalForceScatter, UsedOnlyWhenTheInternalForceIsThePassesOnlyTerm) {
  const Case<3> c = makeCase<3>(ForceSetup{});
  auto scatters = [&](const HourglassSettings& hourglass, Quadrature quadrature,
                      const ViscositySettings& viscosity) {
    TlsphForces<3> forces(c.ref, c.materials, c.materialOf, c.V, hourglass, quadrature, viscosity,
                          0.01);
    return forces.scattersInternalForce();
  };
  const Case<3> q =
      makeCase<3>(ForceSetup{Quadrature::Taylor, GradientCorrection::Quadratic, kEnergy});
  EXPECT_TRUE(scatters(kEnergy, Quadrature::Nodal, {}));
  EXPECT_TRUE(scatters({}, Quadrature::Nodal, {}));
  EXPECT_FALSE(scatters({2.0, HourglassForm::Ganzenmueller, HourglassGradient::Corrected},
                        Quadrature::Nodal, {}));
  EXPECT_FALSE(scatters(kEnergy, Quadrature::Nodal, ViscositySettings{1.0, 0.0}));
  TlsphForces<3> linearF(q.ref, q.materials, q.materialOf, q.V,
                         {10.0, HourglassForm::Energy, HourglassGradient::Linear},
                         Quadrature::Taylor);
  EXPECT_FALSE(linearF.scattersInternalForce());
  TlsphForces<3> taylor(q.ref, q.materials, q.materialOf, q.V, kEnergy, Quadrature::Taylor);
  EXPECT_TRUE(taylor.scattersInternalForce());
}
