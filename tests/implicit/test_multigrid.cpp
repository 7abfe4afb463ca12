// The multigrid preconditioner of the Newton solver ([static] preconditioner): the interpolation
// between lattices reproduces linear fields; the V-cycle is a symmetric positive definite
// operator (what conjugate gradients need); Newton with it reaches the Cholesky-preconditioned
// equilibrium; its iteration count does not grow with the resolution; `auto` picks it only where
// it pays and keeps the direct factor for nearly incompressible bodies.
#include <gtest/gtest.h>

#ifdef _OPENMP
#include <omp.h>
#endif

#include <filesystem>
#include <random>
#include <string>

#include "app/RunSimulation.hpp"
#include "geometry/Lattice.hpp"
#include "implicit/ConjugateGradients.hpp"
#include "implicit/MlsInterpolation.hpp"
#include "implicit/MultigridPreconditioner.hpp"
#include "scene/Config.hpp"
#include "scene/InputError.hpp"
#include "scene/SceneBuilder.hpp"

using namespace tlsph;
namespace fs = std::filesystem;

namespace {

template <int D>
std::vector<Vec<D>> randomPoints(std::mt19937& rng, int count, double size) {
  std::uniform_real_distribution<double> u(0.0, size);
  std::vector<Vec<D>> X(count);
  for (auto& x : X)
    for (int a = 0; a < D; ++a)
      x[a] = u(rng);
  return X;
}

template <int D>
void expectLinearFieldsReproduced(std::uint32_t seed) {
  std::mt19937 rng(seed);
  const double dx = 0.1;
  std::array<int, D> ten;
  ten.fill(10);
  const auto sources = cellCentredLattice<D>(Vec<D>::Zero(), ten, dx);  // a 1 x 1 (x 1) block
  // Targets inside, away from where the support leaves the block's hull thin.
  auto targets = randomPoints<D>(rng, 200, 0.8);
  for (auto& t : targets)
    t.array() += 0.1;
  const Kernel<D> kernel(KernelType::WendlandC2, 2.1 * dx);
  const InterpolationMatrix W = mlsInterpolation<D>(targets, sources, kernel);
  std::normal_distribution<double> n;
  const double a = n(rng);
  Vec<D> b;
  for (int k = 0; k < D; ++k)
    b[k] = n(rng);
  Eigen::VectorXd f(sources.size());
  for (std::size_t c = 0; c < sources.size(); ++c)
    f[c] = a + b.dot(sources[c]);
  const Eigen::VectorXd g = W * f;
  for (std::size_t t = 0; t < targets.size(); ++t)
    EXPECT_NEAR(g[t], a + b.dot(targets[t]), 1e-12) << "target " << t;
}

TEST(MlsInterpolation, ReproducesLinearFields2D) {
  expectLinearFieldsReproduced<2>(1);
}
TEST(MlsInterpolation, ReproducesLinearFields3D) {
  expectLinearFieldsReproduced<3>(2);
}

TEST(MlsInterpolation, WrapsAroundPeriodicAxes) {
  // Periodic along x: a target at x = 0.01 takes sources near x = 1 as its left neighbours, so
  // a field linear in y alone and one periodic-smooth in x are carried exactly / to first order.
  const double dx = 0.1;
  const auto sources = cellCentredLattice<2>(Vec<2>::Zero(), {10, 10}, dx);
  PeriodicBox<2> box;
  box.periodic = {true, false};
  box.length = Vec<2>(1.0, 0.0);
  const Kernel<2> kernel(KernelType::WendlandC2, 2.1 * dx);
  const std::vector<Vec<2>> targets = {Vec<2>(0.01, 0.5), Vec<2>(0.99, 0.37)};
  const InterpolationMatrix W = mlsInterpolation<2>(targets, sources, kernel, box);
  Eigen::VectorXd f(sources.size());
  for (std::size_t c = 0; c < sources.size(); ++c)
    f[c] = 2.0 + 3.0 * sources[c].y();
  const Eigen::VectorXd g = W * f;
  EXPECT_NEAR(g[0], 3.5, 1e-12);
  EXPECT_NEAR(g[1], 3.11, 1e-12);
  // Weights from both sides of the seam.
  bool left = false, right = false;
  for (InterpolationMatrix::InnerIterator it(W, 0); it; ++it) {
    left |= sources[it.col()].x() > 0.8;
    right |= sources[it.col()].x() < 0.2;
  }
  EXPECT_TRUE(left && right);
}

TEST(MlsInterpolation, FallsBackToTheMeanWithTooFewSources) {
  // Two sources on a line cannot carry a 2D linear fit: the kernel-weighted mean, weights
  // summing to one.
  const std::vector<Vec<2>> sources = {Vec<2>(0.0, 0.0), Vec<2>(0.1, 0.0)};
  const std::vector<Vec<2>> targets = {Vec<2>(0.03, 0.05), Vec<2>(5.0, 5.0)};
  const Kernel<2> kernel(KernelType::WendlandC2, 0.21);
  const InterpolationMatrix W = mlsInterpolation<2>(targets, sources, kernel);
  EXPECT_NEAR(W.row(0).sum(), 1.0, 1e-14);
  EXPECT_GT(W.coeff(0, 0), W.coeff(0, 1));  // the nearer source weighs more
  EXPECT_EQ(W.row(1).nonZeros(), 0);        // out of reach of every source
}

// A 3D plate clamped on two opposite faces, or a 2D cantilever, as scene text.
std::string plate(double dx) {
  return R"([scene]
dimension = 3
dx = )" + std::to_string(dx) +
         R"(
[material.plate]
model = saint-venant-kirchhoff
density = 1000
youngs_modulus = 1.0e7
poisson_ratio = 0.3
[body.plate]
shape = box
lower = 0 0 0
upper = 0.2 0.1 0.02
[clamp.left]
face = x-
[clamp.right]
face = x+
[load.pressure]
face = z+
type = traction
value = 0 0 -1000
ramp = 0.001
[static]
solver = newton
tolerance = 1e-9
[time]
end = 1
[output]
fields = none
)";
}

std::string beam(double dx, double gravity) {
  return R"([scene]
dimension = 2
dx = )" + std::to_string(dx) +
         R"(
[material.rubber]
model = neo-hookean
density = 1000
youngs_modulus = 1.0e6
poisson_ratio = 0.3
[body.beam]
shape = box
lower = 0 0
upper = 0.4 0.05
[clamp.root]
face = x-
[gravity]
acceleration = 0 )" +
         std::to_string(-gravity) + R"(
[static]
solver = newton
tolerance = 1e-9
[time]
end = 20
[output]
fields = none
)";
}

template <int D>
struct Result {
  RunSummary summary;
  SceneSetup<D> setup;
};

template <int D>
Result<D> run(const std::string& text, const std::string& name,
              const std::vector<std::string>& overrides = {}) {
  const fs::path dir = fs::temp_directory_path() / ("tlsph_multigrid_" + name);
  fs::remove_all(dir);
  std::vector<std::string> all = overrides;
  all.push_back("--output.directory=" + dir.string());
  Result<D> r{{}, buildScene<D>(Config::parse(text, name + ".ini", all))};
  r.summary = runSimulation(r.setup, RunOptions{}, [](const Solver<D>&) {});
  fs::remove_all(dir);
  return r;
}

template <int D>
double largestDisplacement(const SceneSetup<D>& s) {
  double m = 0.0;
  for (const auto& u : s.scene.particles.displacement)
    m = std::max(m, u.norm());
  return m;
}

template <int D>
double largestDifference(const SceneSetup<D>& a, const SceneSetup<D>& b) {
  double m = 0.0;
  for (std::size_t i = 0; i < a.scene.particles.displacement.size(); ++i)
    m = std::max(m, (a.scene.particles.displacement[i] - b.scene.particles.displacement[i]).norm());
  return m;
}

TEST(Multigrid, VCycleIsSymmetricPositiveDefinite) {
  // The plate at 8 x 4 x 2 ... : 2 levels; deformed by its load first, so the tangent and the
  // coarse level's interpolated state are not the reference ones.
  SceneSetup<3> setup = buildScene<3>(Config::parse(plate(0.005), "plate.ini"));
  Solver<3> solver(setup.scene, setup.solver);
  solver.beginStaticStep(solver.rampEnd());
  std::mt19937 rng(7);
  std::normal_distribution<double> n(0.0, 1e-4);
  for (Index i = 0; i < setup.scene.particles.size(); ++i)
    if (setup.scene.particles.motion[i] == Motion::Free)
      for (int a = 0; a < 3; ++a)
        setup.scene.particles.displacement[i][a] = n(rng);
  solver.reevaluate();
  DofMap<3> dofs(setup.scene.particles, setup.scene.mirrorGhosts);
  auto& s = setup.scene;
  TangentStiffness<3> K(solver.reference(), s.materials, s.particles.material, s.particles.volume,
                        s.hourglass(), dofs, s.quadrature);
  K.update(solver.forces().deformationGradient());
  K.updateQuadrature(solver.forces().quadrature(), solver.forces().deformationGradient());
  std::vector<std::unique_ptr<Scene<3>>> coarse;
  coarse.push_back(setup.coarsen(2));
  ASSERT_TRUE(coarse.front());
  MultigridPreconditioner<3> M(s, dofs, K, std::move(coarse), setup.solver);
  std::string why;
  ASSERT_TRUE(M.update(solver.rampEnd(), s.particles.displacement, why)) << why;
  ASSERT_EQ(M.levelCount(), 2);
  EXPECT_GT(M.unknowns()[0], 4 * M.unknowns()[1]);
  const Index size = K.size();
  for (int trial = 0; trial < 3; ++trial) {
    const Eigen::VectorXd x = Eigen::VectorXd::Random(size), y = Eigen::VectorXd::Random(size);
    const Eigen::VectorXd Mx = M.apply(x), My = M.apply(y);
    EXPECT_NEAR(x.dot(My), y.dot(Mx), 1e-10 * std::abs(x.dot(My)) + 1e-300);
    EXPECT_GT(x.dot(Mx), 0.0);
  }
  // An approximate inverse: conjugate gradients need far fewer iterations with it than with
  // the diagonal blocks alone.
  Eigen::VectorXd b = Eigen::VectorXd::Random(size), x = Eigen::VectorXd::Zero(size);
  auto apply = [&](const Eigen::VectorXd& v, Eigen::VectorXd& Kv) { K.apply(v, Kv); };
  const auto withMultigrid = conjugateGradients(
      apply, [&](const Eigen::VectorXd& r) { return M.apply(r); }, b, x, 1e-8 * b.norm(), 1000,
      1000);
  const auto blocks = K.diagonalBlocks();
  x.setZero();
  const auto withJacobi = conjugateGradients(
      apply,
      [&](const Eigen::VectorXd& r) {
        Eigen::VectorXd z(r.size());
        for (std::size_t p = 0; p < blocks.size(); ++p)
          z.segment<3>(3 * p) = blocks[p].ldlt().solve(Vec<3>(r.segment<3>(3 * p)));
        return z;
      },
      b, x, 1e-8 * b.norm(), 3000, 3000);
  EXPECT_LE(withMultigrid.residual, 1e-8 * b.norm());
  EXPECT_LT(withMultigrid.iterations * 5, withJacobi.iterations)
      << withMultigrid.iterations << " against " << withJacobi.iterations;
}

TEST(Multigrid, NewtonReachesTheCholeskyEquilibrium3D) {
  const auto direct = run<3>(plate(0.005), "p_chol", {"--static.preconditioner=cholesky"});
  const auto multi = run<3>(plate(0.005), "p_mg", {"--static.preconditioner=multigrid"});
  ASSERT_EQ(direct.summary.newton->levels, 1);
  ASSERT_EQ(multi.summary.newton->levels, 2);
  const double w = largestDisplacement(direct.setup);
  EXPECT_GT(w, 1e-6);
  // Both solve to an out-of-balance ratio of 1e-9.
  EXPECT_LT(largestDifference(direct.setup, multi.setup), 1e-6 * w);
}

TEST(Multigrid, NewtonFollowsALargeDeflectionPath) {
  // Tip deflection about a quarter of the length, in four load steps: the coarse level is
  // renewed at the interpolated deformed state.
  const auto direct =
      run<2>(beam(0.00625, 400.0), "b_chol",
             {"--gravity.ramp=1", "--static.load_steps=4", "--static.preconditioner=cholesky"});
  const auto multi =
      run<2>(beam(0.00625, 400.0), "b_mg",
             {"--gravity.ramp=1", "--static.load_steps=4", "--static.preconditioner=multigrid"});
  const double w = largestDisplacement(direct.setup);
  EXPECT_GT(w, 0.05);
  EXPECT_LT(largestDifference(direct.setup, multi.setup), 1e-6 * w);
}

TEST(Multigrid, IterationsDoNotGrowWithResolution) {
  // The cantilever at 8, 16 and 32 particles through its depth: the conjugate-gradient count of
  // the whole solve stays flat (measured 38, 38, 39), where an unpreconditioned one would double
  // with each halving of dx.
  std::vector<long> iterations;
  for (double dx : {0.00625, 0.003125, 0.0015625}) {
    const auto r = run<2>(beam(dx, 1.0), "flat", {"--static.preconditioner=multigrid"});
    iterations.push_back(r.summary.newton->krylovIterations);
  }
  EXPECT_LE(iterations[2], iterations[0] * 5 / 4)
      << iterations[0] << ", " << iterations[1] << ", " << iterations[2];
  EXPECT_LE(iterations[1], iterations[0] * 5 / 4);
}

TEST(Multigrid, AutoChoosesByProblemSizeAndCompressibility) {
  // Small: the direct factor.
  EXPECT_EQ(run<2>(beam(0.0125, 1.0), "auto_small").summary.newton->levels, 1);
  // From 15,000 unknowns on: the multigrid (the beam at 32 through: 8192 particles x 2).
  const auto large = run<2>(beam(0.0015625, 1.0), "auto_large");
  EXPECT_GE(large.summary.newton->levels, 2);
  EXPECT_NE(large.summary.newton->linearSolver.find("multigrid"), std::string::npos);
  // Nearly incompressible: the factor, whatever the size.
  const auto rubber =
      run<2>(beam(0.0015625, 1.0), "auto_rubber", {"--material.rubber.poisson_ratio=0.49"});
  EXPECT_EQ(rubber.summary.newton->levels, 1);
}

TEST(Multigrid, AutoFallsBackToTheFactorWhenItsIterationStalls) {
  // Cook's membrane at nu = 0.4999 (the validation scene, 2,868 unknowns): with the Poisson
  // bar lifted, auto takes the multigrid, whose block-Jacobi smoothing cannot damp the
  // volumetric modes; the stall hands the solve to the Cholesky factor, which converges.
  const std::string file =
      std::string(TLSPH_SOURCE_DIR) + "/validation/scenes/cook_membrane_incompressible.ini";
  auto solve = [&](const std::string& preconditioner) {
    const fs::path dir = fs::temp_directory_path() / ("tlsph_multigrid_fallback_" + preconditioner);
    fs::remove_all(dir);
    SceneSetup<2> s = buildScene<2>(
        Config::read(file, {"--static.solver=newton", "--static.preconditioner=" + preconditioner,
                            "--output.fields=none", "--output.directory=" + dir.string()}));
    s.run.newton.autoMultigridUnknowns = 1000;
    s.run.newton.autoPoissonLimit = 0.5;
    const RunSummary summary = runSimulation(s, RunOptions{}, [](const Solver<2>&) {});
    fs::remove_all(dir);
    return std::make_pair(summary, s.scene.particles.displacement);
  };
  const auto [fallback, u] = solve("auto");
  const auto [direct, v] = solve("cholesky");
  ASSERT_TRUE(fallback.newton && direct.newton);
  EXPECT_EQ(fallback.newton->levels, 1);
  EXPECT_NE(fallback.newton->linearSolver.find("multigrid given up"), std::string::npos)
      << fallback.newton->linearSolver;
  double scale = 0.0, difference = 0.0;
  for (std::size_t i = 0; i < u.size(); ++i) {
    scale = std::max(scale, v[i].norm());
    difference = std::max(difference, (u[i] - v[i]).norm());
  }
  EXPECT_GT(scale, 0.0);
  EXPECT_LT(difference, 1e-5 * scale);
}

TEST(Multigrid, AThinBodyWithoutACoarseLevelKeepsTheFactor) {
  // Two particles through the thickness: at twice the spacing one, where the correction tensor
  // is singular. auto runs with the factor; multigrid asked for is refused, saying why.
  auto setup = [&](const std::string& preconditioner) {
    SceneSetup<3> s = buildScene<3>(Config::parse(
        plate(0.0125), "thin.ini",
        {"--body.plate.upper=0.3 0.3 0.025", "--static.preconditioner=" + preconditioner,
         "--output.directory=" + (fs::temp_directory_path() / "tlsph_multigrid_thin").string()}));
    s.run.newton.autoMultigridUnknowns = 100;
    return s;
  };
  SceneSetup<3> automatic = setup("auto");
  fs::remove_all(fs::temp_directory_path() / "tlsph_multigrid_thin");
  const RunSummary r = runSimulation(automatic, RunOptions{}, [](const Solver<3>&) {});
  fs::remove_all(fs::temp_directory_path() / "tlsph_multigrid_thin");
  ASSERT_TRUE(r.newton);
  EXPECT_EQ(r.outcome, RunOutcome::Converged);
  EXPECT_EQ(r.newton->levels, 1);
  SceneSetup<3> asked = setup("multigrid");
  Solver<3> solver(asked.scene, asked.solver);
  try {
    NewtonSolver<3> newton(asked.scene, solver, asked.run.newton, asked.coarsen, asked.solver);
    FAIL() << "a multigrid without a coarse level was accepted";
  } catch (const SetupError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("twice its particle spacing"), std::string::npos) << m;
    EXPECT_NE(m.find("preconditioner = cholesky"), std::string::npos) << m;
  }
}

TEST(Multigrid, GivesBitwiseEqualResultsOnAnyThreadCount) {
  // The diagonal blocks, the Lanczos bound and the interpolations are all summed in a fixed
  // order: the same iterations and the same bits on 1 and 3 threads.
  std::vector<Result<3>> results;
  for ([[maybe_unused]] int threads : {1, 3}) {
#ifdef _OPENMP
    omp_set_num_threads(threads);
#endif
    results.push_back(run<3>(plate(0.005), "threads", {"--static.preconditioner=multigrid"}));
  }
#ifdef _OPENMP
  omp_set_num_threads(1);
#endif
  EXPECT_EQ(results[0].summary.newton->krylovIterations,
            results[1].summary.newton->krylovIterations);
  const auto& a = results[0].setup.scene.particles.displacement;
  const auto& b = results[1].setup.scene.particles.displacement;
  for (std::size_t i = 0; i < a.size(); ++i)
    ASSERT_EQ(a[i], b[i]) << "particle " << i;
}

TEST(Multigrid, RejectsAnUnknownPreconditioner) {
  try {
    buildScene<2>(Config::parse(beam(0.0125, 1.0), "bad.ini", {"--static.preconditioner=amg"}));
    FAIL() << "accepted preconditioner = amg";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("preconditioner"), std::string::npos) << m;
    EXPECT_NE(m.find("multigrid"), std::string::npos) << m;
  }
}

}  // namespace
