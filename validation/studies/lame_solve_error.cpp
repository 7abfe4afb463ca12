// Where the Lame ring's hoop-stress error at the bore comes from
// (validation/lame_cylinder_notes.md).
//
// The ring is linear (linear-elastic material, dead pressure), so the solved displacement is
// exactly u_h = u_e + K^-1 r(u_e): the exact Lame field plus the response to the discrete
// equations' residual at the exact field. Splitting r by radius (the bore nodes, the layers
// under them, the rest of the body) and solving for each part shows which particles' residual
// puts how much error into the hoop stress recovered at the bore (method = surface, docs/method.md
// section 3.5). Also prints the spectrum of the tangential displacement error along the bore.
//
//   cmake --build build --target tlsph_study_lame_solve_error
//   build/tlsph_study_lame_solve_error 16 kernel.integration_constraint=true kernel.support=2.5
//
// The first argument is the number of elements through the wall; the others are overrides of
// validation/scenes/lame_ring.ini. K is applied as the change of the net force (exact for this
// linear problem) inside the project's conjugate gradients, unpreconditioned.
#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "explicit/Solver.hpp"
#include "implicit/ConjugateGradients.hpp"
#include "implicit/NewtonSolver.hpp"
#include "materials/Material.hpp"
#include "method/SurfaceStress.hpp"
#include "scene/Config.hpp"
#include "scene/SceneBuilder.hpp"

using namespace tlsph;

namespace {

// validation/scenes/lame_ring.ini: the ring's radii and the bore's pressure.
constexpr double kA = 0.05, kB = 0.1, kP = 1e8;

// The plane-strain Lame solution u_r = A r + B / r for the scene's material.
struct Lame {
  double lambda, mu, A, B, hoop, ua;
  explicit Lame(const ElasticConstants& c) : lambda(c.lambda), mu(c.mu) {
    B = kP / (2 * (lambda + mu) / (kB * kB) + 2 * mu / (kA * kA));
    A = -B / (kB * kB);
    hoop = 2 * (lambda + mu) * A + 2 * mu * B / (kA * kA);
    ua = A * kA + B / kA;
  }
};

using Field = std::vector<Vec<2>>;

struct Statistics {
  double mean = 0.0, rms = 0.0, worst = 0.0;
};

Statistics statisticsOf(const std::vector<double>& e) {
  Statistics s;
  for (double x : e) {
    s.mean += x / e.size();
    s.worst = std::max(s.worst, std::abs(x));
  }
  for (double x : e)
    s.rms += (x - s.mean) * (x - s.mean) / e.size();
  s.rms = std::sqrt(s.rms);
  return s;
}

}  // namespace

int main(int argc, char** argv) try {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s THROUGH [section.key=value ...]\n", argv[0]);
    return 1;
  }
  const double through = std::atof(argv[1]);
  std::vector<std::string> overrides = {"scene.dx=" + std::to_string((kB - kA) / through),
                                        "output.fields=none"};
  for (int k = 2; k < argc; ++k)
    overrides.emplace_back(argv[k]);
  auto setup =
      buildScene<2>(Config::read(TLSPH_SOURCE_DIR "/validation/scenes/lame_ring.ini", overrides));
  Scene<2>& scene = setup.scene;
  auto& particles = scene.particles;
  const auto n = particles.size();
  const double dx = setup.dx;

  const Material& material = scene.materials[0];
  const Lame lame(elasticConstants(material));
  Solver<2> solver(scene, setup.solver);
  NewtonSettings settings;
  settings.tolerance = 1e-10;
  settings.linearTolerance = 1e-10;
  settings.preconditioner = NewtonPreconditioner::Cholesky;
  NewtonSolver<2> newton(scene, solver, settings);
  newton.run([] { return true; });
  const Field solved = particles.displacement;

  Field exact(n);
  for (Index i = 0; i < n; ++i) {
    const Vec<2> X = particles.referencePosition[i];
    const double r = X.norm();
    exact[i] = (lame.A * r + lame.B / r) * X / r;
  }
  // The net force (internal plus the loads at full pressure) on the free particles.
  auto netForce = [&](const Field& u, Field& f) {
    for (Index i = 0; i < n; ++i)
      if (particles.motion[i] == Motion::Free) particles.displacement[i] = u[i];
    solver.reevaluate();
    f.assign(n, Vec<2>::Zero());
    for (Index i = 0; i < n; ++i)
      if (particles.motion[i] == Motion::Free) f[i] = solver.netForce(i);
  };
  Field residual, loadOnly;
  netForce(exact, residual);
  netForce(Field(n, Vec<2>::Zero()), loadOnly);
  // K v = -(the change of the net force), exact for this linear problem; plain conjugate
  // gradients (the fixed particles' rows and right sides are zero).
  auto solveK = [&](const Field& rhs) {
    auto flat = [](const Field& f) {
      return Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(f[0].data(), 2 * f.size()));
    };
    Field v(n), Kv;
    auto applyK = [&](const Eigen::VectorXd& x, Eigen::VectorXd& out) {
      Eigen::Map<Eigen::VectorXd>(v[0].data(), 2 * n) = x;
      netForce(v, Kv);
      out = flat(loadOnly) - flat(Kv);
    };
    const Eigen::VectorXd b = flat(rhs);
    Eigen::VectorXd x = Eigen::VectorXd::Zero(b.size());
    conjugateGradients(
        applyK, [](const Eigen::VectorXd& r) { return r; }, b, x, 1e-12 * b.norm(), 100000, 100000);
    Field out(n);
    Eigen::Map<Eigen::VectorXd>(out[0].data(), 2 * n) = x;
    return out;
  };

  const SurfacePatch<2>& bore = setup.surfaces.at("bore");
  std::vector<SurfaceStencil<2>> stencils;
  for (std::size_t k = 0; k < bore.particles.size(); ++k) {
    std::string why;
    auto s = surfaceStencil<2>(bore.particles[k], particles.referencePosition, bore.particles,
                               bore.areaVector, bore.areaVector[k], scene.supportRadius, why);
    if (!s)
      throw std::runtime_error("bore particle " + std::to_string(bore.particles[k]) + ": " + why);
    stencils.push_back(*s);
  }
  // The recovered hoop stress's error at every bore node, per cent.
  auto hoopErrors = [&](const Field& u) {
    std::vector<double> e;
    for (const auto& s : stencils) {
      const Vec<2> N = s.normal;
      const Mat<2> H =
          recoveredDisplacementGradient<2>(s, u, material, Vec<2>(-kP * N), 0.0, Mat<2>::Zero());
      const Mat<2> strain = 0.5 * (H + H.transpose());
      const Vec<2> t(-N.y(), N.x());
      const double hoop = lame.lambda * strain.trace() + 2 * lame.mu * t.dot(strain * t);
      e.push_back(100 * (hoop / lame.hoop - 1));
    }
    return statisticsOf(e);
  };
  auto print = [](const char* what, const Statistics& s) {
    std::printf("%-34s %+7.3f %7.3f %7.2f\n", what, s.mean, s.rms, s.worst);
  };

  std::printf("Lame ring, %g through (dx %g m, %zu particles, %zu bore nodes)\n", through, dx,
              static_cast<std::size_t>(n), bore.particles.size());
  std::printf("%-34s %7s %7s %7s\n", "recovered hoop stress, % vs Lame", "mean", "rms", "worst");
  print("exact field", hoopErrors(exact));
  print("solved (Newton)", hoopErrors(solved));
  {
    std::vector<double> e;
    for (Index i : bore.particles) {
      const Vec<2> X = particles.referencePosition[i];
      e.push_back(100 * (solved[i].dot(X.normalized()) / lame.ua - 1));
    }
    print("u_r at the bore nodes, % vs Lame", statisticsOf(e));
  }
  Field e = solveK(residual);
  Field u(n);
  for (Index i = 0; i < n; ++i)
    u[i] = exact[i] + e[i];
  print("exact + K^-1 r (the same)", hoopErrors(u));
  std::printf(
      "the response to the residual of one region only (residual: rms per node, in p dx):\n");
  const double edges[] = {0.5, 1.5, 2.5, 4.5, 1e9};
  double from = -1.0;  // the bore nodes lie on the circle, within rounding
  for (double to : edges) {
    Field part(n, Vec<2>::Zero());
    double sum = 0.0;
    int count = 0;
    for (Index i = 0; i < n; ++i) {
      const double depth = (particles.referencePosition[i].norm() - kA) / dx;
      if (depth >= from && depth < to && particles.motion[i] == Motion::Free) {
        part[i] = residual[i];
        sum += residual[i].squaredNorm();
        ++count;
      }
    }
    const Field ep = solveK(part);
    for (Index i = 0; i < n; ++i)
      u[i] = exact[i] + ep[i];
    char what[80];
    std::snprintf(what, sizeof what, "depth %.1f-%.1f dx: %4d, r %.4f", std::max(from, 0.0),
                  std::min(to, 99.0), count, std::sqrt(sum / std::max(count, 1)) / (kP * dx));
    print(what, hoopErrors(u));
    from = to;
  }

  // The tangential displacement error along the bore, by wave number around the circle.
  std::vector<std::pair<double, double>> along;
  for (Index i : bore.particles) {
    const Vec<2> X = particles.referencePosition[i];
    const Vec<2> t = Vec<2>(-X.y(), X.x()).normalized();
    along.emplace_back(std::atan2(X.y(), X.x()), (solved[i] - exact[i]).dot(t) / lame.ua);
  }
  std::sort(along.begin(), along.end());
  const std::size_t m = along.size();
  std::vector<double> power(m / 2 + 1, 0.0);
  double total = 0.0, square = 0.0;
  for (std::size_t k = 0; k < power.size(); ++k) {
    std::complex<double> c = 0.0;
    for (std::size_t j = 0; j < m; ++j)
      c += along[j].second * std::polar(1.0, -2.0 * M_PI * double(k * j) / double(m));
    power[k] = std::norm(c);
    if (k > 0) total += power[k];
  }
  for (const auto& [angle, value] : along)
    square += value * value / m;
  auto share = [&](std::size_t lo, std::size_t hi) {
    double s = 0.0;
    for (std::size_t k = lo; k < std::min(hi, power.size()); ++k)
      s += power[k];
    return s / total;
  };
  std::printf(
      "tangential displacement error along the bore: rms %.2e of u_r(a); share of wave numbers "
      "1-3 / 4-9 / 10-19 / 20+: %.2f / %.2f / %.2f / %.2f\n",
      std::sqrt(square), share(1, 4), share(4, 10), share(10, 20), share(20, power.size()));
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "error: %s\n", e.what());
  return 1;
}
