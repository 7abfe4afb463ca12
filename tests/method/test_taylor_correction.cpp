// The Taylor quadrature term (method/TaylorCorrection.hpp) on the plain loops: the force is
// -dE/du of E = sum_I V_I psi(F_I) + E_q (+ E_hg) by central differences; E_q is zero for
// every affine field and rigid rotation and positive otherwise; the second gradients are exact
// for quadratic fields; and on a cell-centred lattice the corrected energy of a quadratic
// displacement field is the exact integral of the linear-elastic energy density over the body,
// where the nodal sum alone misses 1/n^2 of the bending energy. With general quadrature moments
// (random ones, and a simplex mesh's hat moments): the same gradient, linearisation and zeros,
// and on an irregular mesh's nodes the corrected energy of a quadratic field is again the exact
// integral, where the lattice cells' moments are not.
#include <gtest/gtest.h>

#include <cmath>
#include <variant>

#include "PlainEvaluator.hpp"

using namespace tlsph;
using namespace tlsph::testing;

namespace {

constexpr double kDx = 0.01;

template <int D>
Scene<D> blockScene(const std::string& material, double alpha, double jitter, std::mt19937& rng,
                    bool taylor = true) {
  return taylorBlockScene<D>(material, alpha, jitter, rng, kDx, taylor);
}

template <int D>
Scene<D> momentScene(const std::string& material, double alpha, std::mt19937& rng) {
  Scene<D> scene = blockScene<D>(material, alpha, 0.15, rng);
  addRandomMoments<D>(scene, rng, kDx);
  return scene;
}

template <int D>
std::vector<Vec<D>> bentField(const std::vector<Vec<D>>& X, std::mt19937& rng, double noise) {
  // affine, bent (curvature up to 2/m) and noisy
  const Mat<D> A = randomMatrix<D>(rng, 0.1);
  const Vec<D> bend = randomVector<D>(rng, 0.01);
  std::vector<Vec<D>> u(X.size());
  for (std::size_t i = 0; i < X.size(); ++i)
    u[i] = A * X[i] + X[i].squaredNorm() / kDx * bend + randomVector<D>(rng, noise * kDx);
  return u;
}

template <int D>
void expectForceIsMinusEnergyGradient(const std::string& material, double alpha, std::uint32_t seed,
                                      bool moments = false) {
  std::mt19937 rng(seed);
  PlainEvaluator<D> eval(moments ? momentScene<D>(material, alpha, rng)
                                 : blockScene<D>(material, alpha, 0.15, rng));
  ASSERT_NE(eval.forces().quadrature(), nullptr);
  double fmax = 0.0;
  const auto u = bentField<D>(eval.X(), rng, 0.03);
  ASSERT_TRUE(std::isfinite(eval.energy(u)));  // (a NaN would pass the comparison)
  const double worst = energyGradientError<D>(eval, u, 1e-6 * kDx, fmax);
  SCOPED_TRACE(material + " alpha " + std::to_string(alpha) + " D=" + std::to_string(D));
  EXPECT_GT(fmax, 0.0);
  EXPECT_LT(worst, 1e-6 * fmax);
}

// E_q alone: the difference of the strain energies with and without the term.
template <int D>
double quadratureEnergy(PlainEvaluator<D>& taylor, PlainEvaluator<D>& nodal,
                        const std::vector<Vec<D>>& u) {
  return taylor.energy(u) - nodal.energy(u);
}

template <int D>
void expectZeroForAffineAndRigidMotion(const std::string& material, std::uint32_t seed,
                                       bool moments = false) {
  std::mt19937 rng(seed);
  auto scene =
      moments ? momentScene<D>(material, 0.0, rng) : blockScene<D>(material, 0.0, 0.15, rng);
  PlainEvaluator<D> taylor(scene);
  scene.quadrature = Quadrature::Nodal;
  PlainEvaluator<D> nodal(scene);
  const auto bent = bentField<D>(taylor.X(), rng, 0.0);
  const double reference = quadratureEnergy(taylor, nodal, bent);
  if (!moments) {  // (the offset's part has either sign)
    EXPECT_GT(reference, 0.0);
  }
  EXPECT_NE(reference, 0.0);
  const Mat<D> A = randomMatrix<D>(rng, 0.1), R = randomRotation<D>(rng);
  const Vec<D> b = randomVector<D>(rng, 0.01);
  std::vector<Vec<D>> affine(taylor.size()), rotated(taylor.size());
  for (Index i = 0; i < taylor.size(); ++i) {
    affine[i] = A * taylor.X()[i] + b;
    rotated[i] = (R - Mat<D>::Identity()) * taylor.X()[i] + b;
  }
  taylor.force(affine);
  const double Eaffine = taylor.forces().strainEnergy();
  nodal.force(affine);
  EXPECT_LT(std::abs(Eaffine - nodal.forces().strainEnergy()), 1e-12 * Eaffine) << material;
  const bool objective = std::visit([](const auto& m) { return m.objective; }, scene.materials[0]);
  if (objective) {  // the bent field rotated: the same E_q
    std::vector<Vec<D>> bentRotated(taylor.size());
    for (Index i = 0; i < taylor.size(); ++i)
      bentRotated[i] = R * (taylor.X()[i] + bent[i]) - taylor.X()[i];
    EXPECT_NEAR(quadratureEnergy(taylor, nodal, bentRotated), reference, 1e-9 * std::abs(reference))
        << material;
    taylor.force(rotated);
    EXPECT_LT(std::abs(taylor.forces().strainEnergy()), 1e-9 * std::abs(reference)) << material;
  }
}

template <int D>
void expectMomentumConservation(const std::string& material, std::uint32_t seed) {
  std::mt19937 rng(seed);
  PlainEvaluator<D> eval(blockScene<D>(material, 0.0, 0.15, rng));
  const auto u = bentField<D>(eval.X(), rng, 0.03);
  const auto f = eval.force(u);
  const auto x = eval.currentPositions(u);
  Vec<D> total = Vec<D>::Zero();
  double scale = 0.0, armScale = 0.0;
  for (Index i = 0; i < eval.size(); ++i) {
    total += f[i];
    scale += f[i].norm();
    armScale += x[i].norm() * f[i].norm();
  }
  EXPECT_LT(total.norm(), 1e-13 * scale) << material;
  const bool objective =
      std::visit([](const auto& m) { return m.objective; }, eval.scene().materials[0]);
  if (objective) {
    EXPECT_LT(torque<D>(x, f).norm(), 1e-12 * armScale) << material;
  }
}

// u_i = A_ij X_j + 1/2 B_ijk X_j X_k (B symmetric in j, k); the exact integral of the linear
// elastic energy density over the block by 3-point Gauss rules per axis (exact: the density is
// quadratic in X).
template <int D>
void expectExactForQuadraticFields(std::uint32_t seed) {
  std::mt19937 rng(seed);
  Scene<D> scene = blockScene<D>("linear-elastic", 0.0, 0.0, rng);
  Vec<D> upper = Vec<D>::Zero();
  for (const auto& X : scene.particles.referencePosition)
    upper = upper.cwiseMax(X);
  upper.array() += 0.5 * kDx;
  const double amplitude = 1e-7;
  const Mat<D> A = randomMatrix<D>(rng, amplitude);
  std::array<Mat<D>, D> B;  // B[i](j, k)
  for (auto& b : B) {
    b = randomMatrix<D>(rng, amplitude / kDx);
    b = Mat<D>(0.5 * (b + b.transpose()).eval());
  }
  auto gradient = [&](const Vec<D>& X) {
    Mat<D> H = A;
    for (int i = 0; i < D; ++i)
      H.row(i) += (B[i] * X).transpose();
    return H;
  };
  const auto& c = elasticConstants(scene.materials[0]);
  auto density = [&](const Vec<D>& X) {
    const Mat<D> H = gradient(X);
    const Mat<D> eps = 0.5 * (H + H.transpose());
    return 0.5 * c.lambda * eps.trace() * eps.trace() + c.mu * (eps.array() * eps.array()).sum();
  };
  const double g = std::sqrt(0.6);
  const std::array<double, 3> node = {-g, 0.0, g}, weight = {5.0 / 9, 8.0 / 9, 5.0 / 9};
  double exact = 0.0;
  std::array<int, D> idx{};
  const int total = D == 2 ? 9 : 27;
  for (int m = 0; m < total; ++m) {
    int r = m;
    Vec<D> X;
    double w = 1.0;
    for (int a = 0; a < D; ++a) {
      idx[a] = r % 3;
      r /= 3;
      X[a] = 0.5 * upper[a] * (1.0 + node[idx[a]]);
      w *= 0.5 * upper[a] * weight[idx[a]];
    }
    exact += w * density(X);
  }
  PlainEvaluator<D> corrected(scene);
  scene.quadrature = Quadrature::Nodal;
  PlainEvaluator<D> nodal(scene);
  EXPECT_TRUE(corrected.reference().linearFallback.empty());
  std::vector<Vec<D>> u(corrected.size());
  for (Index i = 0; i < corrected.size(); ++i) {
    const Vec<D>& X = scene.particles.referencePosition[i];
    u[i] = A * X;
    for (int k = 0; k < D; ++k)
      u[i][k] += 0.5 * X.dot(B[k] * X);
  }
  const double Ec = corrected.energy(u), En = nodal.energy(u);
  SCOPED_TRACE("D=" + std::to_string(D) + " nodal " + std::to_string(En / exact));
  // F and its gradient are exact at every particle (the quadratic fit)
  for (Index i = 0; i < corrected.size(); ++i) {
    const Vec<D>& X = scene.particles.referencePosition[i];
    const Mat<D> H = gradient(X);
    EXPECT_LT((corrected.forces().deformationGradient()[i] - Mat<D>::Identity() - H).norm(),
              1e-8 * A.norm());
    const auto& G = corrected.forces().secondGradients()[i];
    for (int a = 0; a < D; ++a)
      for (int k = 0; k < D; ++k)
        EXPECT_LT((G[a].row(k) - B[k].row(a)).norm(), 1e-8 * B[k].norm()) << i << " " << a;
  }
  EXPECT_NEAR(Ec, exact, 1e-6 * exact);
  EXPECT_GT(std::abs(En - exact), 1e-3 * exact);  // the nodal sum alone is not exact
}

// linearised() is the directional derivative of stress() and hyperstress(): central
// differences of both along a random direction v about a bent state, at every particle.
template <int D>
void expectLinearisation(const std::string& material, std::uint32_t seed, bool moments = false) {
  std::mt19937 rng(seed);
  PlainEvaluator<D> eval(moments ? momentScene<D>(material, 0.0, rng)
                                 : blockScene<D>(material, 0.0, 0.15, rng));
  const TaylorCorrection<D>& q = *eval.forces().quadrature();
  const auto& ref = eval.reference();
  const auto u = bentField<D>(eval.X(), rng, 0.03);
  std::vector<Vec<D>> v(u.size());
  for (auto& vi : v)
    vi = randomVector<D>(rng, kDx);
  using Gradients = typename TaylorCorrection<D>::Gradients;
  auto along = [&](double s) {
    std::vector<Vec<D>> w(u.size());
    for (std::size_t j = 0; j < u.size(); ++j)
      w[j] = u[j] + s * v[j];
    return w;
  };
  const double h = 1e-6;
  const auto w0 = along(0.0), wp = along(h), wm = along(-h);
  double worstP = 0.0, worstR = 0.0, scaleP = 0.0, scaleR = 0.0;
  for (Index i = 0; i < eval.size(); ++i) {
    auto F = [&](const std::vector<Vec<D>>& w) {
      return deformationGradientAt<D>(ref.neighbours, ref.correctedGradient, w, i);
    };
    const Gradients G = q.secondGradients(i, w0), Gp = q.secondGradients(i, wp),
                    Gm = q.secondGradients(i, wm);
    const Mat<D> dH = displacementGradientAt<D>(ref.neighbours, ref.correctedGradient, v, i);
    const auto d = q.linearised(i, F(w0), G, dH, q.secondGradients(i, v));
    const Mat<D> dP = (q.stress(i, F(wp), Gp) - q.stress(i, F(wm), Gm)) / (2.0 * h);
    worstP = std::max(worstP, (d.stress - dP).cwiseAbs().maxCoeff());
    scaleP = std::max(scaleP, dP.cwiseAbs().maxCoeff());
    const Gradients Rp = q.hyperstress(i, F(wp), Gp), Rm = q.hyperstress(i, F(wm), Gm);
    for (int a = 0; a < D; ++a) {
      const Mat<D> dR = (Rp[a] - Rm[a]) / (2.0 * h);
      worstR = std::max(worstR, (d.hyperstress[a] - dR).cwiseAbs().maxCoeff());
      scaleR = std::max(scaleR, dR.cwiseAbs().maxCoeff());
    }
  }
  SCOPED_TRACE(material + " D=" + std::to_string(D));
  EXPECT_GT(scaleR, 0.0);
  EXPECT_LT(worstR, 1e-7 * scaleR);
  // e_a = sym(G_a): no P^q without an offset
  const bool small = material == "linear-elastic" && !moments;
  if (small) {
    EXPECT_EQ(scaleP, 0.0);
  } else {
    EXPECT_GT(scaleP, 0.0);
    EXPECT_LT(worstP, 1e-7 * scaleP);
  }
}

// A box of cells x dx (nodes on a grid, the interior ones moved by up to 0.25 dx per axis), each
// cell cut into simplices (2D: two triangles along alternating diagonals; 3D: the six tetrahedra
// around its main diagonal). Particles at the nodes with the hat functions' volumes and moments:
// with barycentric lambda, x - X_I = sum_k lambda_k (v_k - v_I) on a simplex T and
//   int_T lambda^alpha dV = |T| d! prod_k alpha_k! / (d + |alpha|)!.
template <int D>
struct SimplexMesh {
  std::vector<Vec<D>> node;
  std::vector<std::array<int, D + 1>> simplex;
  Vec<D> upper;
};

template <int D>
SimplexMesh<D> simplexMesh(const std::array<int, D>& cells, std::mt19937& rng) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  SimplexMesh<D> m;
  std::array<int, D> nodes;
  int total = 1;
  for (int a = 0; a < D; ++a) {
    nodes[a] = cells[a] + 1;
    total *= nodes[a];
    m.upper[a] = cells[a] * kDx;
  }
  auto index = [&](const std::array<int, D>& c) {
    int k = 0;
    for (int a = D - 1; a >= 0; --a)
      k = k * nodes[a] + c[a];
    return k;
  };
  m.node.resize(total);
  for (int k = 0; k < total; ++k) {
    std::array<int, D> c;
    int r = k;
    bool interior = true;
    for (int a = 0; a < D; ++a) {
      c[a] = r % nodes[a];
      r /= nodes[a];
      interior = interior && c[a] > 0 && c[a] < cells[a];
    }
    for (int a = 0; a < D; ++a)
      m.node[index(c)][a] = c[a] * kDx + (interior ? 0.25 * kDx * unit(rng) : 0.0);
  }
  int cellCount = 1;
  for (int a = 0; a < D; ++a)
    cellCount *= cells[a];
  for (int k = 0; k < cellCount; ++k) {
    std::array<int, D> c;
    int r = k, parity = 0;
    for (int a = 0; a < D; ++a) {
      c[a] = r % cells[a];
      r /= cells[a];
      parity += c[a];
    }
    auto corner = [&](std::array<int, D> offset) {
      for (int a = 0; a < D; ++a)
        offset[a] += c[a];
      return index(offset);
    };
    if constexpr (D == 2) {
      const int n00 = corner({0, 0}), n10 = corner({1, 0}), n01 = corner({0, 1}),
                n11 = corner({1, 1});
      if (parity % 2) {
        m.simplex.push_back({n00, n10, n11});
        m.simplex.push_back({n00, n11, n01});
      } else {
        m.simplex.push_back({n00, n10, n01});
        m.simplex.push_back({n10, n11, n01});
      }
    } else {  // the paths from (0,0,0) to (1,1,1) along the axes in each of the 6 orders
      std::array<int, 3> order = {0, 1, 2};
      do {
        std::array<int, 3> at = {0, 0, 0};
        std::array<int, 4> t;
        t[0] = corner(at);
        for (int s = 0; s < 3; ++s) {
          at[order[s]] = 1;
          t[s + 1] = corner(at);
        }
        m.simplex.push_back(t);
      } while (std::next_permutation(order.begin(), order.end()));
    }
  }
  return m;
}

int factorial(int n) {
  return n <= 1 ? 1 : n * factorial(n - 1);
}

// Particles at the mesh's nodes with V_I, mu_I and N_I of their hats.
template <int D>
Scene<D> meshScene(const SimplexMesh<D>& m, const std::string& material, bool moments) {
  Scene<D> scene = sceneOf<D>(m.node, kDx, 2.4, testMaterial(material), 0.0);
  scene.gradientCorrection = GradientCorrection::Quadratic;
  scene.quadrature = Quadrature::Taylor;
  auto& p = scene.particles;
  const std::size_t n = m.node.size();
  std::vector<double> V(n, 0.0);
  std::vector<Vec<D>> m1(n, Vec<D>::Zero());
  std::vector<Mat<D>> M2(n, Mat<D>::Zero());
  for (const auto& t : m.simplex) {
    Mat<D> edges;
    for (int a = 0; a < D; ++a)
      edges.col(a) = m.node[t[a + 1]] - m.node[t[0]];
    const double volume = std::abs(edges.determinant()) / factorial(D);
    // int lambda^alpha over T for the exponents of lambda_I lambda_k (lambda_l)
    auto integral = [&](std::array<int, D + 1> alpha) {
      int sum = 0, product = 1;
      for (int e : alpha) {
        sum += e;
        product *= factorial(e);
      }
      return volume * factorial(D) * product / double(factorial(D + sum));
    };
    for (int i = 0; i <= D; ++i) {
      const Vec<D>& Xi = m.node[t[i]];
      std::array<int, D + 1> alpha{};
      alpha[i] = 1;
      V[t[i]] += integral(alpha);
      for (int k = 0; k <= D; ++k) {
        auto ak = alpha;
        ++ak[k];
        m1[t[i]] += integral(ak) * (m.node[t[k]] - Xi);
        for (int l = 0; l <= D; ++l) {
          auto akl = ak;
          ++akl[l];
          M2[t[i]] += integral(akl) * (m.node[t[k]] - Xi) * (m.node[t[l]] - Xi).transpose();
        }
      }
    }
  }
  const double rho = density(scene.materials[0]);
  for (std::size_t i = 0; i < n; ++i) {
    p.volume[i] = V[i];
    p.mass[i] = rho * V[i];
  }
  if (moments) {
    p.quadratureOffset.resize(n);
    p.quadratureSpread.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      p.quadratureOffset[i] = m1[i] / V[i];
      p.quadratureSpread[i] = M2[i] / V[i];
    }
  }
  return scene;
}

// u_i = A_ij X_j + 1/2 B_ijk X_j X_k on an irregular simplex mesh's nodes: with the hats'
// moments E + E_q is the exact integral of the linear-elastic energy density over the box (3-point
// Gauss rules per axis, exact for the quadratic density); with the lattice cells' it is not.
template <int D>
void expectExactOnAMesh(std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::array<int, D> cells;
  cells.fill(D == 2 ? 6 : 4);
  cells[0] = D == 2 ? 8 : 5;
  const SimplexMesh<D> mesh = simplexMesh<D>(cells, rng);
  const double amplitude = 1e-7;
  const Mat<D> A = randomMatrix<D>(rng, amplitude);
  std::array<Mat<D>, D> B;
  for (auto& b : B) {
    b = randomMatrix<D>(rng, amplitude / kDx);
    b = Mat<D>(0.5 * (b + b.transpose()).eval());
  }
  Scene<D> scene = meshScene<D>(mesh, "linear-elastic", true);
  const auto& c = elasticConstants(scene.materials[0]);
  auto density = [&](const Vec<D>& X) {
    Mat<D> H = A;
    for (int i = 0; i < D; ++i)
      H.row(i) += (B[i] * X).transpose();
    const Mat<D> eps = 0.5 * (H + H.transpose());
    return 0.5 * c.lambda * eps.trace() * eps.trace() + c.mu * (eps.array() * eps.array()).sum();
  };
  const double g = std::sqrt(0.6);
  const std::array<double, 3> node = {-g, 0.0, g}, weight = {5.0 / 9, 8.0 / 9, 5.0 / 9};
  double exact = 0.0;
  for (int m = 0; m < (D == 2 ? 9 : 27); ++m) {
    int r = m;
    Vec<D> X;
    double w = 1.0;
    for (int a = 0; a < D; ++a) {
      const int q = r % 3;
      r /= 3;
      X[a] = 0.5 * mesh.upper[a] * (1.0 + node[q]);
      w *= 0.5 * mesh.upper[a] * weight[q];
    }
    exact += w * density(X);
  }
  PlainEvaluator<D> moments(scene);
  PlainEvaluator<D> lattice(meshScene<D>(mesh, "linear-elastic", false));
  EXPECT_TRUE(moments.reference().linearFallback.empty());
  std::vector<Vec<D>> u(moments.size());
  for (Index i = 0; i < moments.size(); ++i) {
    const Vec<D>& X = mesh.node[i];
    u[i] = A * X;
    for (int k = 0; k < D; ++k)
      u[i][k] += 0.5 * X.dot(B[k] * X);
  }
  const double Em = moments.energy(u), El = lattice.energy(u);
  SCOPED_TRACE("D=" + std::to_string(D) + " moments " + std::to_string(Em / exact - 1.0) +
               " lattice " + std::to_string(El / exact - 1.0));
  EXPECT_NEAR(Em, exact, 1e-10 * exact);
  EXPECT_GT(std::abs(El - exact), 1e-3 * exact);  // the cells' moments are not the hats'
}

const char* const kMaterials[] = {"linear-elastic", "saint-venant-kirchhoff", "neo-hookean",
                                  "mooney-rivlin"};

}  // namespace

TEST(TaylorCorrection, ForceIsMinusEnergyGradient2D) {
  for (const char* m : kMaterials)
    expectForceIsMinusEnergyGradient<2>(m, 0.0, 11);
  expectForceIsMinusEnergyGradient<2>("neo-hookean", 10.0, 12);
}
TEST(TaylorCorrection, ForceIsMinusEnergyGradient3D) {
  for (const char* m : kMaterials)
    expectForceIsMinusEnergyGradient<3>(m, 0.0, 13);
  expectForceIsMinusEnergyGradient<3>("saint-venant-kirchhoff", 10.0, 14);
}
TEST(TaylorCorrection, ZeroForAffineFieldsAndRigidMotion) {
  for (const char* m : kMaterials) {
    expectZeroForAffineAndRigidMotion<2>(m, 15);
    expectZeroForAffineAndRigidMotion<3>(m, 16);
  }
}
TEST(TaylorCorrection, ConservesMomentum) {
  for (const char* m : kMaterials) {
    expectMomentumConservation<2>(m, 17);
    expectMomentumConservation<3>(m, 18);
  }
}
TEST(TaylorCorrection, ExactForQuadraticFieldsOnALattice) {
  expectExactForQuadraticFields<2>(31);
  expectExactForQuadraticFields<3>(32);
}
TEST(TaylorCorrection, LinearisationIsTheDirectionalDerivative) {
  for (const char* m : kMaterials) {
    expectLinearisation<2>(m, 41);
    expectLinearisation<3>(m, 42);
  }
}

TEST(TaylorCorrection, ForceIsMinusEnergyGradientWithMoments) {
  for (const char* m : {"linear-elastic", "neo-hookean"}) {
    expectForceIsMinusEnergyGradient<2>(m, 0.0, 51, true);
    expectForceIsMinusEnergyGradient<3>(m, 0.0, 52, true);
  }
  expectForceIsMinusEnergyGradient<3>("saint-venant-kirchhoff", 10.0, 53, true);
}
TEST(TaylorCorrection, ZeroForAffineFieldsAndRigidMotionWithMoments) {
  for (const char* m : {"linear-elastic", "neo-hookean"}) {
    expectZeroForAffineAndRigidMotion<2>(m, 54, true);
    expectZeroForAffineAndRigidMotion<3>(m, 55, true);
  }
}
TEST(TaylorCorrection, LinearisationWithMoments) {
  for (const char* m : kMaterials) {
    expectLinearisation<2>(m, 56, true);
    expectLinearisation<3>(m, 57, true);
  }
}
TEST(TaylorCorrection, ExactForQuadraticFieldsOnASimplexMeshWithItsMoments) {
  expectExactOnAMesh<2>(61);
  expectExactOnAMesh<3>(62);
}
