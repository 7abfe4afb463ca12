// The tangent stiffness K = -df/du on the unknowns (TangentStiffness): its matrix-free product
// is the central finite difference of the force for every material, both corrections, with and
// without the energy penalty (on either F), with prescribed particles and mirrored ghosts; the
// assembled matrix equals it without the penalty and bounds it from above with the penalty; K is
// symmetric (the force is -dE/du).
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>

#include "DifferencedStiffness.hpp"
#include "TestSupport.hpp"
#include "explicit/Solver.hpp"
#include "implicit/DofMap.hpp"
#include "implicit/TangentStiffness.hpp"
#include "method/PairForces.hpp"
#include "scene/SceneBuilder.hpp"

using namespace tlsph;
using namespace tlsph::testing;

namespace {

constexpr double kDx = 0.01;

struct Case {
  std::string material;
  GradientCorrection correction;
  double alpha;
  HourglassGradient hourglassGradient = HourglassGradient::Corrected;
};

// A jittered block; the particles with x < 1.5 dx are held: the first layer prescribed, the
// second (2D: also) as mirrored ghosts of the body's particles mirrored across x = 1.5 dx... kept
// simple: layer 0 prescribed (fixed), layer 1 mirrored ghosts of layer 2 (odd reflection) when
// `ghosts` is set.
template <int D>
Scene<D> heldBlock(const Case& c, bool ghosts, std::mt19937& rng) {
  std::array<int, D> counts;
  counts.fill(D == 2 ? 5 : 3);
  counts[0] = D == 2 ? 7 : 5;
  auto X = perturbedBlock<D>(counts, kDx, 0.15, rng);
  Scene<D> scene = sceneOf<D>(X, kDx, 2.4, testMaterial(c.material), c.alpha);
  scene.gradientCorrection = c.correction;
  scene.hourglassGradient = c.hourglassGradient;
  auto& p = scene.particles;
  Prescription<D> clamp;
  clamp.name = "held";
  std::vector<Index> layer2;
  for (Index i = 0; i < p.size(); ++i) {
    const int layer = static_cast<int>(std::floor(p.referencePosition[i].x() / kDx + 1e-9));
    if (layer == 0) {
      p.motion[i] = Motion::Prescribed;
      clamp.particles.push_back(i);
    }
  }
  scene.prescriptions.push_back(clamp);
  if (ghosts) {
    // Ghosts of layer-2 particles: layer-1 particles mirror the layer-2 particle nearest their
    // reflection across x = 1.5 dx (an odd reflection with an unequal spacing is still a valid
    // linear constraint: that is all the tangent test needs).
    for (Index i = 0; i < p.size(); ++i) {
      const int layer = static_cast<int>(std::floor(p.referencePosition[i].x() / kDx + 1e-9));
      if (layer != 1) continue;
      Vec<D> target = p.referencePosition[i];
      target.x() = 3.0 * kDx - target.x();
      Index best = -1;
      for (Index j = 0; j < p.size(); ++j)
        if (p.motion[j] == Motion::Free && j != i &&
            static_cast<int>(std::floor(p.referencePosition[j].x() / kDx + 1e-9)) == 2 &&
            (best < 0 || (p.referencePosition[j] - target).norm() <
                             (p.referencePosition[best] - target).norm()))
          best = j;
      p.motion[i] = Motion::Mirrored;
      MirrorGhost m;
      m.ghost = i;
      m.mirror = best;
      m.w1 = -0.8;  // any weights: a general linear constraint
      // the second particle: the next one in +x from the mirror
      Index second = -1;
      for (Index j = 0; j < p.size(); ++j)
        if (p.motion[j] == Motion::Free && j != best &&
            static_cast<int>(std::floor(p.referencePosition[j].x() / kDx + 1e-9)) == 3 &&
            (second < 0 || (p.referencePosition[j] - p.referencePosition[best]).norm() <
                               (p.referencePosition[second] - p.referencePosition[best]).norm()))
          second = j;
      m.second = second;
      m.w2 = 0.3;
      scene.mirrorGhosts.push_back(m);
    }
  }
  return scene;
}

// Dense K from the matrix-free product, from central differences of the net force, and from the
// assembly (lower triangle mirrored).
template <int D>
struct Matrices {
  Eigen::MatrixXd applied, differenced, assembled;
  std::vector<Mat<D>> diagonal;  // TangentStiffness::diagonalBlocks()
};

// The free particles moved by a random affine field plus noise; the solver re-evaluated there.
template <int D>
void deformRandomly(Scene<D>& scene, Solver<D>& solver, std::mt19937& rng) {
  auto& p = scene.particles;
  const Mat<D> A = randomMatrix<D>(rng, 0.08);
  for (Index i = 0; i < p.size(); ++i)
    if (p.motion[i] == Motion::Free)
      p.displacement[i] = A * p.referencePosition[i] + randomVector<D>(rng, 0.04 * kDx);
  solver.reevaluate();
}

template <int D>
Matrices<D> matricesOf(Scene<D>& scene, std::mt19937& rng) {
  Solver<D> solver(scene);
  auto& p = scene.particles;
  deformRandomly(scene, solver, rng);
  DofMap<D> dofs(p, scene.mirrorGhosts);
  TangentStiffness<D> K(solver.reference(), scene.materials, p.material, p.volume,
                        scene.hourglass(), dofs);
  K.update(solver.forces().deformationGradient());
  const Index n = K.size();
  Matrices<D> m;
  m.applied.resize(n, n);
  Eigen::VectorXd e = Eigen::VectorXd::Zero(n), column;
  for (Index k = 0; k < n; ++k) {
    e.setZero();
    e[k] = 1.0;
    K.apply(e, column);
    m.applied.col(k) = column;
  }
  const Eigen::SparseMatrix<double> full = K.assemble().template selfadjointView<Eigen::Lower>();
  m.assembled = Eigen::MatrixXd(full);
  m.diagonal = K.diagonalBlocks();
  // -df/du_k by central differences of the net force on the unknowns
  m.differenced = differencedStiffness(solver, p.displacement, dofs.freeParticles(), 1e-6 * kDx);
  return m;
}

template <int D>
void expectTangent(const Case& c, bool ghosts, std::uint32_t seed) {
  std::mt19937 rng(seed);
  Scene<D> scene = heldBlock<D>(c, ghosts, rng);
  const Matrices<D> m = matricesOf<D>(scene, rng);
  const double scale = m.differenced.cwiseAbs().maxCoeff();
  SCOPED_TRACE(c.material + " " + gradientCorrectionName(c.correction) + " alpha " +
               std::to_string(c.alpha) + (ghosts ? " with ghosts" : "") +
               " D=" + std::to_string(D));
  // Central differences of a smooth force: truncation ~h^2, round-off ~eps |f| / h.
  EXPECT_LT((m.applied - m.differenced).cwiseAbs().maxCoeff(), 1e-5 * scale);
  EXPECT_LT((m.applied - m.applied.transpose()).cwiseAbs().maxCoeff(), 1e-10 * scale);
  // The diagonal blocks without the assembly are the assembled matrix's.
  ASSERT_EQ(static_cast<Index>(m.diagonal.size()) * D, m.assembled.rows());
  for (std::size_t q = 0; q < m.diagonal.size(); ++q)
    EXPECT_LT(
        (m.diagonal[q] - m.assembled.template block<D, D>(D * q, D * q)).cwiseAbs().maxCoeff(),
        1e-12 * scale);
  if (c.alpha == 0.0) {
    EXPECT_LT((m.assembled - m.applied).cwiseAbs().maxCoeff(), 1e-10 * scale);
  } else {
    // The assembled penalty part bounds the exact one: assembled - K is positive semidefinite,
    // and not zero (the bound is not the exact Hessian).
    const Eigen::MatrixXd gap = m.assembled - m.applied;
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(0.5 * (gap + gap.transpose()));
    EXPECT_GT(eig.eigenvalues().minCoeff(), -1e-10 * scale);
    EXPECT_GT(eig.eigenvalues().maxCoeff(), 1e-6 * scale);
  }
}

const std::vector<std::string> kMaterials = {"linear-elastic", "saint-venant-kirchhoff",
                                             "neo-hookean", "mooney-rivlin"};

TEST(TangentStiffness, MatchesFiniteDifferencesWithoutPenalty2D) {
  std::uint32_t seed = 1;
  for (const auto& material : kMaterials)
    for (auto correction : {GradientCorrection::Linear, GradientCorrection::Quadratic})
      expectTangent<2>({material, correction, 0.0}, false, seed++);
}

TEST(TangentStiffness, MatchesFiniteDifferencesWithoutPenalty3D) {
  std::uint32_t seed = 11;
  for (const auto& material : kMaterials)
    for (auto correction : {GradientCorrection::Linear, GradientCorrection::Quadratic})
      expectTangent<3>({material, correction, 0.0}, false, seed++);
}

TEST(TangentStiffness, MatchesFiniteDifferencesWithPenalty) {
  std::uint32_t seed = 21;
  for (auto correction : {GradientCorrection::Linear, GradientCorrection::Quadratic}) {
    expectTangent<2>({"neo-hookean", correction, 10.0}, false, seed++);
    expectTangent<3>({"saint-venant-kirchhoff", correction, 10.0}, false, seed++);
  }
  // the penalty on the linear F while the stress uses the quadratic one
  expectTangent<2>({"neo-hookean", GradientCorrection::Quadratic, 10.0, HourglassGradient::Linear},
                   false, seed++);
  expectTangent<3>(
      {"mooney-rivlin", GradientCorrection::Quadratic, 30.0, HourglassGradient::Linear}, false,
      seed++);
}

TEST(TangentStiffness, ChainsMirroredGhostsAndEliminatesPrescribedParticles) {
  std::uint32_t seed = 31;
  for (double alpha : {0.0, 10.0}) {
    expectTangent<2>({"neo-hookean", GradientCorrection::Quadratic, alpha}, true, seed++);
    expectTangent<3>({"saint-venant-kirchhoff", GradientCorrection::Quadratic, alpha}, true,
                     seed++);
  }
}

// The tangent's products run on the fast passes (the run's force pass for F and grad grad u,
// the fused penalty and the linearised Taylor term); here K v is held to the central difference
// of the plain force of method/PairForces, with the Taylor quadrature and the energy penalty on
// either F, along random directions v.
template <int D>
void expectTangentOfThePlainForce(const Case& c, std::uint32_t seed) {
  std::mt19937 rng(seed);
  Scene<D> scene = heldBlock<D>(c, false, rng);
  scene.quadrature = Quadrature::Taylor;
  auto& p = scene.particles;
  Solver<D> solver(scene);
  deformRandomly(scene, solver, rng);
  DofMap<D> dofs(p, scene.mirrorGhosts);
  TangentStiffness<D> K(solver.reference(), scene.materials, p.material, p.volume,
                        scene.hourglass(), dofs, scene.quadrature);
  K.update(solver.forces().deformationGradient());
  K.updateQuadrature(solver.forces().quadrature(), solver.forces().deformationGradient());
  PairForces<D> plain(solver.reference(), scene.materials, p.material, p.volume, scene.hourglass(),
                      scene.quadrature);
  const auto& free = dofs.freeParticles();
  auto netForce = [&](double s, const Eigen::VectorXd& v) {
    std::vector<Vec<D>> u = p.displacement, f;
    for (std::size_t d = 0; d < free.size(); ++d)
      u[free[d]] += s * v.template segment<D>(D * d);
    plain.compute(u, f);
    Eigen::VectorXd out(D * free.size());
    for (std::size_t d = 0; d < free.size(); ++d)
      out.template segment<D>(D * d) = f[free[d]];
    return out;
  };
  SCOPED_TRACE(c.material + " " + gradientCorrectionName(c.correction) + " alpha " +
               std::to_string(c.alpha) + " D=" + std::to_string(D));
  for (int trial = 0; trial < 3; ++trial) {
    Eigen::VectorXd v(K.size()), Kv;
    for (Eigen::Index k = 0; k < v.size(); ++k)
      v[k] = std::uniform_real_distribution<double>(-1.0, 1.0)(rng);
    K.apply(v, Kv);
    const double h = 1e-6 * kDx;
    const Eigen::VectorXd fd = -(netForce(h, v) - netForce(-h, v)) / (2.0 * h);
    EXPECT_LT((Kv - fd).norm(), 1e-6 * fd.norm());
  }
}

TEST(TangentStiffness, MatchesFiniteDifferencesOfThePlainForce) {
  std::uint32_t seed = 51;
  for (const std::string material : {"linear-elastic", "neo-hookean"})
    for (double alpha : {0.0, 10.0}) {
      expectTangentOfThePlainForce<2>({material, GradientCorrection::Quadratic, alpha}, seed++);
      expectTangentOfThePlainForce<3>({material, GradientCorrection::Quadratic, alpha}, seed++);
    }
  expectTangentOfThePlainForce<2>(
      {"mooney-rivlin", GradientCorrection::Quadratic, 10.0, HourglassGradient::Linear}, seed++);
  expectTangentOfThePlainForce<3>(
      {"saint-venant-kirchhoff", GradientCorrection::Quadratic, 10.0, HourglassGradient::Linear},
      seed++);
}

TEST(TangentStiffness, RejectsTheTextbookHourglassForm) {
  std::mt19937 rng(41);
  Scene<2> scene = heldBlock<2>({"neo-hookean", GradientCorrection::Linear, 10.0}, false, rng);
  scene.hourglassForm = HourglassForm::Ganzenmueller;
  Solver<2> solver(scene);
  DofMap<2> dofs(scene.particles, scene.mirrorGhosts);
  EXPECT_THROW(TangentStiffness<2>(solver.reference(), scene.materials, scene.particles.material,
                                   scene.particles.volume, scene.hourglass(), dofs),
               SetupError);
}

}  // namespace

namespace {

// A scene built from a scene file (mirrored clamp, gravity): K v against the central difference
// of the net force along random directions v, at the undeformed and at a deformed state.
TEST(TangentStiffness, MatchesFiniteDifferencesOnASceneFileBeam) {
  for (const std::string model : {"linear-elastic", "neo-hookean", "saint-venant-kirchhoff"}) {
    const std::string text =
        clampedBeamText(0.5, model, "[gravity]\nacceleration = 0 0 -1\n[hourglass]\nalpha = 0\n");
    SceneSetup<3> setup = buildScene<3>(Config::parse(text, "beam.ini"));
    Scene<3>& scene = setup.scene;
    Solver<3> solver(scene);
    DofMap<3> dofs(scene.particles, scene.mirrorGhosts);
    TangentStiffness<3> K(solver.reference(), scene.materials, scene.particles.material,
                          scene.particles.volume, scene.hourglass(), dofs, scene.quadrature);
    std::mt19937 rng(5);
    const auto& free = dofs.freeParticles();
    for (int state = 0; state < 2; ++state) {
      if (state == 1)
        for (Index i : free)
          scene.particles.displacement[i] = randomVector<3>(rng, 1e-4);
      solver.reevaluate();
      K.update(solver.forces().deformationGradient());
      K.updateQuadrature(solver.forces().quadrature(), solver.forces().deformationGradient());
      auto netForce = [&] {
        Eigen::VectorXd f(3 * free.size());
        for (std::size_t d = 0; d < free.size(); ++d)
          f.segment<3>(3 * d) = solver.netForce(free[d]);
        return f;
      };
      Eigen::VectorXd v(3 * free.size()), Kv;
      for (Eigen::Index k = 0; k < v.size(); ++k)
        v[k] = std::uniform_real_distribution<double>(-1.0, 1.0)(rng);
      K.apply(v, Kv);
      const double h = 1e-7;
      auto shift = [&](double s) {
        for (std::size_t d = 0; d < free.size(); ++d)
          scene.particles.displacement[free[d]] += s * v.segment<3>(3 * d);
        solver.reevaluate();
      };
      shift(h);
      const Eigen::VectorXd plus = netForce();
      shift(-2.0 * h);
      const Eigen::VectorXd minus = netForce();
      shift(h);
      const Eigen::VectorXd fd = -(plus - minus) / (2.0 * h);
      EXPECT_LT((Kv - fd).norm(), 1e-6 * fd.norm()) << model << " state " << state;
    }
  }
}

}  // namespace
