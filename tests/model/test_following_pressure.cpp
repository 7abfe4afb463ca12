// A following pressure (FollowingPressure.hpp, [load.NAME] follow = true) on named surfaces of
// meshed bodies: at rest it is the dead pressure where the facets are flat; deformed, its total
// is -p times the current surface's area vector (from the surface's boundary alone, by Stokes);
// its stiffness is the derivative of the force (and not symmetric on an open surface); a rigid
// rotation turns it with the body while the dead pressure keeps its direction.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <utility>

#include "TestSupport.hpp"
#include "explicit/ExternalForces.hpp"
#include "scene/Config.hpp"
#include "scene/InputError.hpp"
#include "scene/SceneBuilder.hpp"

using namespace tlsph;
using namespace tlsph::testing;
namespace fs = std::filesystem;

namespace {

constexpr double kPressure = 3.0e5;

struct ScratchFolder {
  fs::path path;
  ScratchFolder() {
    path = fs::temp_directory_path() /
           ("tlsph-following-" + std::to_string(::getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~ScratchFolder() { fs::remove_all(path); }
};

// A plane strip 0.1 x 0.02 (2D, curves "top" and "left") or a box 1 x 0.5 x 0.5 (3D, surfaces
// "top", "left" and the closed "skin"): flat facets only.
template <int D>
void writeFlatBody(const fs::path& file) {
  std::ofstream out(file);
  if constexpr (D == 2)
    out << "SetFactory(\"OpenCASCADE\");\nRectangle(1) = {0, 0, 0, 0.1, 0.02};\ne = 1e-6;\n"
           "Physical Curve(\"top\") = Curve In BoundingBox{-e, 0.02 - e, -e, 0.1 + e, 0.02 + e, "
           "e};\nPhysical Curve(\"left\") = Curve In BoundingBox{-e, -e, -e, e, 0.02 + e, e};\n"
           "Physical Surface(\"strip\") = {1};\n";
  else
    out << "SetFactory(\"OpenCASCADE\");\nBox(1) = {0, 0, 0, 1, 0.5, 0.5};\ne = 1e-6;\n"
           "Physical Surface(\"top\") = Surface In BoundingBox{-e, -e, 0.5 - e, 1 + e, 0.5 + e, "
           "0.5 + e};\nPhysical Surface(\"left\") = Surface In BoundingBox{-e, -e, -e, e, 0.5 + "
           "e, 0.5 + e};\nPhysical Surface(\"skin\") = Boundary{ Volume{1}; };\n"
           "Physical Volume(\"box\") = {1};\n";
}

// A scene of the body in `file` (dx) with a pressure on `surface`, following or dead.
template <int D>
SceneSetup<D> build(const fs::path& file, double dx, const std::string& surface, bool follow,
                    const fs::path& folder) {
  std::ostringstream s;
  s << "[scene]\ndimension = " << D << "\ndx = " << dx
    << "\n[time]\nend = 1\n[material.rubber]\nmodel = neo-hookean\ndensity = 1000\n"
       "youngs_modulus = 1e6\npoisson_ratio = 0.3\n[body.b]\nshape = mesh\nfile = "
    << file.string() << "\n[load.p]\nsurface = " << surface
    << "\ntype = pressure\nvalue = " << kPressure << "\nfollow = " << (follow ? "true" : "false")
    << "\n";
  return buildScene<D>(Config::parse(s.str(), (folder / "s.ini").string()));
}

// A smooth, nonuniform displacement of about `scale`, plus noise of a tenth of it.
template <int D>
void deform(SceneSetup<D>& setup, double scale, std::mt19937& rng) {
  auto& p = setup.scene.particles;
  for (Index i = 0; i < p.size(); ++i) {
    const Vec<D>& X = p.referencePosition[i];
    Vec<D> u = randomVector<D>(rng, 0.1 * scale);
    u[0] += scale * std::sin(7.0 * X[1] + 3.0 * X[0]);
    u[1] += scale * std::cos(5.0 * X[0]);
    if constexpr (D == 3) u[2] += scale * X[0] * X[1] * 4.0;
    p.displacement[i] = u;
  }
}

template <int D>
Vec<D> sum(const std::vector<Vec<D>>& f) {
  Vec<D> s = Vec<D>::Zero();
  for (const auto& v : f)
    s += v;
  return s;
}

// The current area vector of the facets' surface from its boundary alone (Stokes): 2D, the
// chain's end minus its start turned by -90 degrees; 3D, 1/2 of the sum of x_a x x_b over the
// boundary edges (a, b) (those whose reverse belongs to no facet).
template <int D>
Vec<D> areaVectorFromBoundary(const std::vector<std::array<Index, D>>& facets,
                              const std::vector<Vec<D>>& x) {
  if constexpr (D == 2) {
    std::map<Index, int> ends;  // +1 where a facet starts, -1 where one ends
    for (const auto& f : facets) {
      ++ends[f[0]];
      --ends[f[1]];
    }
    Vec<2> chord = Vec<2>::Zero();  // end - start; zero on a closed curve
    for (const auto& [i, n] : ends)
      chord -= n * x[i];
    return Vec<2>(chord.y(), -chord.x());
  } else {
    std::map<std::pair<Index, Index>, int> edges;
    for (const auto& f : facets)
      for (int a = 0; a < 3; ++a)
        ++edges[{f[a], f[(a + 1) % 3]}];
    Vec<3> s = Vec<3>::Zero();
    for (const auto& [e, n] : edges)
      if (!edges.count({e.second, e.first})) s += 0.5 * x[e.first].cross(x[e.second]);
    return s;
  }
}

template <int D>
std::vector<Vec<D>> positions(const ParticleSet<D>& p) {
  std::vector<Vec<D>> x(p.size());
  for (Index i = 0; i < p.size(); ++i)
    x[i] = p.referencePosition[i] + p.displacement[i];
  return x;
}

template <int D>
const FollowingPressure<D>& following(const SceneSetup<D>& s) {
  return *s.scene.loads.at(0).following;
}

// The following force at rest against the dead one, on a body with flat facets only.
template <int D>
void atRestEqualsDead() {
  ScratchFolder dir;
  writeFlatBody<D>(dir.path / "body.geo");
  const double dx = D == 2 ? 0.005 : 0.125;
  const auto dead = build<D>(dir.path / "body.geo", dx, "top", false, dir.path);
  const auto follow = build<D>(dir.path / "body.geo", dx, "top", true, dir.path);
  ASSERT_TRUE(follow.scene.loads[0].following);
  ASSERT_FALSE(dead.scene.loads[0].following);
  const auto fDead = ExternalForces<D>(dead.scene).force();
  const auto fFollow = ExternalForces<D>(follow.scene).force();
  const double scale = kPressure * dead.surfaces.at("top").measure;
  double worst = 0.0;
  for (std::size_t i = 0; i < fDead.size(); ++i)
    worst = worseOf(worst, (fDead[i] - fFollow[i]).norm());
  EXPECT_LT(worst, 1e-14 * scale);
  EXPECT_GT(sum(fFollow).norm(), 0.99 * scale);
}

TEST(FollowingPressure, AtRestEqualsTheDeadPressureOnFlatFacets2D) {
  atRestEqualsDead<2>();
}
TEST(FollowingPressure, AtRestEqualsTheDeadPressureOnFlatFacets3D) {
  atRestEqualsDead<3>();
}

// On a curved surface the dead pressure is integrated on the order-2 facets, the following one
// on the flat facets through the particles: at rest they differ by O((h/R)^2), the chords'.
TEST(FollowingPressure, AtRestOnACurveDiffersFromTheDeadByTheChordsSecondOrder) {
  ScratchFolder dir;
  const fs::path ring = fs::path(TLSPH_SOURCE_DIR) / "tests/geometry/data/ring.geo";
  const double h = 0.25;  // on the bore, R = 1
  const auto dead = build<2>(ring, h, "bore", false, dir.path);
  const auto follow = build<2>(ring, h, "bore", true, dir.path);
  const auto fDead = ExternalForces<2>(dead.scene).force();
  const auto fFollow = ExternalForces<2>(follow.scene).force();
  double worst = 0.0, largest = 0.0;
  for (std::size_t i = 0; i < fDead.size(); ++i) {
    worst = worseOf(worst, (fDead[i] - fFollow[i]).norm());
    largest = std::max(largest, fDead[i].norm());
  }
  EXPECT_LT(worst, h * h * largest);
  EXPECT_GT(worst, 1e-6 * largest);  // not the same integral: the test can tell them apart
}

// Deformed by a nonuniform random field, the forces add up to -p times the current surface's
// area vector; on a closed surface to zero.
template <int D>
void totalIsTheCurrentAreaVector(const fs::path& file, double dx, const std::string& surface,
                                 double displacement) {
  auto setup = build<D>(file, dx, surface, true, file.parent_path());
  std::mt19937 rng(7);
  deform(setup, displacement, rng);
  const auto& fp = following(setup);
  const auto x = positions(setup.scene.particles);
  const Vec<D> expected = -kPressure * areaVectorFromBoundary<D>(fp.facets(), x);
  const Vec<D> total = sum(ExternalForces<D>(setup.scene).force());
  const double scale = kPressure * setup.surfaces.at(surface).measure;
  EXPECT_LT((total - expected).norm(), 1e-12 * scale) << total.transpose();
  // The facets' own sum, the definition, agrees too.
  Vec<D> facets = Vec<D>::Zero();
  for (const auto& e : fp.facets())
    facets += fp.areaVector(e, setup.scene.particles.referencePosition,
                            setup.scene.particles.displacement);
  EXPECT_LT((total + kPressure * facets).norm(), 1e-12 * scale);
  // And it has moved away from the reference one (the test can fail).
  const Vec<D> atRest =
      -kPressure * areaVectorFromBoundary<D>(fp.facets(), setup.scene.particles.referencePosition);
  if (atRest.norm() > 0.0) {
    EXPECT_GT((total - atRest).norm(), 1e-3 * atRest.norm());
  }
}

TEST(FollowingPressure, TotalIsPressureTimesTheCurrentAreaVector2D) {
  ScratchFolder dir;
  writeFlatBody<2>(dir.path / "strip.geo");
  totalIsTheCurrentAreaVector<2>(dir.path / "strip.geo", 0.005, "top", 0.002);
  totalIsTheCurrentAreaVector<2>(fs::path(TLSPH_SOURCE_DIR) / "tests/geometry/data/ring.geo", 0.25,
                                 "bore", 0.05);
}

TEST(FollowingPressure, TotalIsPressureTimesTheCurrentAreaVector3D) {
  ScratchFolder dir;
  writeFlatBody<3>(dir.path / "box.geo");
  totalIsTheCurrentAreaVector<3>(dir.path / "box.geo", 0.125, "top", 0.02);
  totalIsTheCurrentAreaVector<3>(fs::path(TLSPH_SOURCE_DIR) / "tests/geometry/data/box_hole.geo",
                                 0.5, "bore", 0.05);
}

// The stiffness product against a central difference of the force, on random directions and
// on unit ones; on an open surface it is not symmetric.
template <int D>
void tangentIsTheDerivative(const fs::path& file, double dx, const std::string& surface,
                            double displacement, bool open) {
  auto setup = build<D>(file, dx, surface, true, file.parent_path());
  std::mt19937 rng(11);
  deform(setup, displacement, rng);
  const auto& fp = following(setup);
  const auto& X = setup.scene.particles.referencePosition;
  const auto u = setup.scene.particles.displacement;
  const std::size_t n = X.size();
  const double ramp = 0.7;
  auto force = [&](const std::vector<Vec<D>>& w) {
    std::vector<Vec<D>> f(n, Vec<D>::Zero());
    fp.addForce(X, w, ramp, f);
    return f;
  };
  auto product = [&](const std::vector<Vec<D>>& v) {
    std::vector<Vec<D>> Kv(n, Vec<D>::Zero());
    fp.addStiffnessProduct(X, u, ramp, v, Kv);
    return Kv;
  };
  auto check = [&](const std::vector<Vec<D>>& v, const std::string& what) {
    const double eps = 1e-6 * displacement;
    std::vector<Vec<D>> plus = u, minus = u;
    for (std::size_t i = 0; i < n; ++i) {
      plus[i] += eps * v[i];
      minus[i] -= eps * v[i];
    }
    const auto fp1 = force(plus), fm1 = force(minus), Kv = product(v);
    double error = 0.0, size = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      // K = -df/du
      const Vec<D> difference = -(fp1[i] - fm1[i]) / (2.0 * eps);
      error = worseOf(error, (difference - Kv[i]).norm());
      size = std::max(size, difference.norm());
    }
    EXPECT_GT(size, 0.0) << what;
    EXPECT_LT(error, 1e-7 * size) << what;
  };
  for (int trial = 0; trial < 3; ++trial) {
    std::vector<Vec<D>> v(n);
    for (auto& w : v)
      w = randomVector<D>(rng, 1.0);
    check(v, "random direction " + std::to_string(trial));
  }
  // Columns of K: each component of the first surface particles.
  const auto& on = setup.surfaces.at(surface).particles;
  for (std::size_t k = 0; k < 4 && k < on.size(); ++k)
    for (int a = 0; a < D; ++a) {
      std::vector<Vec<D>> v(n, Vec<D>::Zero());
      v[on[k]][a] = 1.0;
      check(v, "unit direction " + std::to_string(on[k]) + "." + std::to_string(a));
    }
  // w . K v against v . K w.
  std::vector<Vec<D>> v(n), w(n);
  for (std::size_t i = 0; i < n; ++i) {
    v[i] = randomVector<D>(rng, 1.0);
    w[i] = randomVector<D>(rng, 1.0);
  }
  const auto Kv = product(v), Kw = product(w);
  double wKv = 0.0, vKw = 0.0, size = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    wKv += w[i].dot(Kv[i]);
    vKw += v[i].dot(Kw[i]);
    size += w[i].norm() * Kv[i].norm();
  }
  if (open)
    EXPECT_GT(std::abs(wKv - vKw), 1e-3 * size)
        << "an open surface's load stiffness is not symmetric";
  else
    EXPECT_LT(std::abs(wKv - vKw), 1e-12 * size)
        << "a closed surface's load stiffness is symmetric";
}

TEST(FollowingPressure, TangentIsTheCentralDifferenceOfTheForce2D) {
  ScratchFolder dir;
  writeFlatBody<2>(dir.path / "strip.geo");
  tangentIsTheDerivative<2>(dir.path / "strip.geo", 0.005, "top", 0.002, true);
  tangentIsTheDerivative<2>(fs::path(TLSPH_SOURCE_DIR) / "tests/geometry/data/ring.geo", 0.25,
                            "bore", 0.05, false);
}

TEST(FollowingPressure, TangentIsTheCentralDifferenceOfTheForce3D) {
  ScratchFolder dir;
  writeFlatBody<3>(dir.path / "box.geo");
  tangentIsTheDerivative<3>(dir.path / "box.geo", 0.125, "top", 0.02, true);
  tangentIsTheDerivative<3>(fs::path(TLSPH_SOURCE_DIR) / "tests/geometry/data/box_hole.geo", 0.5,
                            "bore", 0.05, true);  // a tube, open at both ends
  tangentIsTheDerivative<3>(dir.path / "box.geo", 0.125, "skin", 0.02, false);
}

// u = (R - 1) X + c: the following force turns with the body, the dead one keeps its direction.
template <int D>
void rotatesWithTheBody() {
  ScratchFolder dir;
  writeFlatBody<D>(dir.path / "body.geo");
  const double dx = D == 2 ? 0.005 : 0.125;
  auto follow = build<D>(dir.path / "body.geo", dx, "top", true, dir.path);
  auto dead = build<D>(dir.path / "body.geo", dx, "top", false, dir.path);
  const auto f0 = ExternalForces<D>(follow.scene).force();
  const auto d0 = ExternalForces<D>(dead.scene).force();
  std::mt19937 rng(5);
  const Mat<D> R = randomRotation<D>(rng);
  const Vec<D> c = randomVector<D>(rng, 0.3);
  for (auto* s : {&follow, &dead}) {
    auto& p = s->scene.particles;
    for (Index i = 0; i < p.size(); ++i)
      p.displacement[i] = (R - Mat<D>::Identity()) * p.referencePosition[i] + c;
  }
  const auto f1 = ExternalForces<D>(follow.scene).force();
  const auto d1 = ExternalForces<D>(dead.scene).force();
  double largest = 0.0, rotated = 0.0, kept = 0.0, moved = 0.0;
  for (std::size_t i = 0; i < f0.size(); ++i) {
    largest = std::max(largest, f0[i].norm());
    rotated = worseOf(rotated, (f1[i] - R * f0[i]).norm());
    kept = worseOf(kept, (d1[i] - d0[i]).norm());
    moved = std::max(moved, (f1[i] - f0[i]).norm());
  }
  EXPECT_GT(largest, 0.0);
  EXPECT_LT(rotated, 1e-12 * largest);
  EXPECT_EQ(kept, 0.0);
  EXPECT_GT(moved, 0.1 * largest);  // the rotation is not small: the test can tell
}

TEST(FollowingPressure, RotatesWithARigidRotationWhileTheDeadOneStays2D) {
  rotatesWithTheBody<2>();
}
TEST(FollowingPressure, RotatesWithARigidRotationWhileTheDeadOneStays3D) {
  rotatesWithTheBody<3>();
}

// follow = true is for a pressure on a named surface only; each misuse names its key.
TEST(FollowingPressure, InputErrorsNameTheKey) {
  ScratchFolder dir;
  auto message = [&](const std::string& loads) {
    try {
      buildScene<2>(Config::parse(
          "[scene]\ndimension = 2\ndx = 0.01\n[time]\nend = 1\n[material.m]\nmodel = "
          "neo-hookean\ndensity = 1000\nyoungs_modulus = 1e6\npoisson_ratio = 0.3\n[body.b]\n"
          "shape = box\nlower = 0 0\nupper = 0.2 0.04\n[clamp.c]\nface = x-\n" +
              loads,
          (dir.path / "s.ini").string()));
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::string onFace =
      message("[load.p]\nface = y+\ntype = pressure\nvalue = 1e3\nfollow = true\n");
  EXPECT_NE(onFace.find("[load.p] follow"), std::string::npos) << onFace;
  EXPECT_NE(onFace.find("face y+ of the bounding box has none"), std::string::npos) << onFace;
  const std::string onTraction =
      message("[load.p]\nface = y+\ntype = traction\nvalue = 0 1e3\nfollow = true\n");
  EXPECT_NE(onTraction.find("[load.p] follow: only a pressure follows"), std::string::npos)
      << onTraction;
  const std::string notABool =
      message("[load.p]\nface = y+\ntype = pressure\nvalue = 1e3\nfollow = maybe\n");
  EXPECT_NE(notABool.find("expected true or false"), std::string::npos) << notABool;
  EXPECT_EQ(message("[load.p]\nface = y+\ntype = pressure\nvalue = 1e3\nfollow = false\n"),
            "no error");
}

}  // namespace
