// Bodies from CAD and mesh files through gmsh: particle volumes integrated on the curved
// (order-2) mesh sum to its measure and converge to the CAD measure at the order of the
// geometry, surface nodes lie on the CAD surface, facets face out of the solid, and every kind
// of bad input is rejected with the file and the reason.
//
// The curved-geometry tolerances come from the order-2 (quadratic) interpolation of a circle: N
// equal arcs of angle t = 2 pi / N, each replaced by the parabola through its ends and midpoint,
// give a length short by the fraction t^4 / 960 and a disc short by pi R^2 t^4 / 480 (Taylor
// expansion; the next terms are smaller by t^2). gmsh splits a full circle into equal arcs and
// puts the order-2 node at the arc's midpoint, so these are the predicted errors, not bounds.
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <clocale>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <numbers>
#include <numeric>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "geometry/GmshBody.hpp"

using namespace tlsph;

namespace {

constexpr double kPi = std::numbers::pi;

std::string data(const std::string& name) {
  return std::string(TLSPH_GEOMETRY_DATA) + "/" + name;
}

double sum(const std::vector<double>& v) {
  return std::accumulate(v.begin(), v.end(), 0.0);
}

double relative(double value, double exact) {
  return std::abs(value - exact) / std::abs(exact);
}

// The message of the GeometryError f throws; fails the test when it throws nothing.
template <class F>
std::string errorOf(F&& f) {
  try {
    f();
  } catch (const GeometryError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no GeometryError thrown";
  return {};
}

void expectMessage(const std::string& message, const std::vector<std::string>& parts) {
  for (const auto& part : parts)
    EXPECT_NE(message.find(part), std::string::npos)
        << "message \"" << message << "\" lacks \"" << part << "\"";
}

// Partition of unity: the node volumes (areas) sum to the element-by-element measure.
template <int D>
void expectPartitionOfUnity(const MeshedBody<D>& body) {
  EXPECT_NEAR(sum(body.volume), body.measure, 1e-12 * body.measure);
  EXPECT_GT(*std::min_element(body.volume.begin(), body.volume.end()), 0.0);
  ASSERT_EQ(body.volume.size(), body.position.size());
  for (const auto& [name, surface] : body.surfaces) {
    EXPECT_NEAR(sum(surface.area), surface.measure, 1e-12 * surface.measure) << name;
    ASSERT_EQ(surface.area.size(), surface.nodes.size()) << name;
    EXPECT_TRUE(std::is_sorted(surface.nodes.begin(), surface.nodes.end())) << name;
    EXPECT_EQ(std::adjacent_find(surface.nodes.begin(), surface.nodes.end()), surface.nodes.end());
    // Every facet corner is one of the surface's nodes, and every node a facet corner.
    std::set<Index> corners;
    for (const auto& facet : surface.facets)
      corners.insert(facet.begin(), facet.end());
    EXPECT_EQ(std::vector<Index>(corners.begin(), corners.end()), surface.nodes) << name;
  }
}

// The nodes' hat moments: sum_I V_I (X_I + mu_I) = int x dV and
// sum_I V_I (X_I X_I^T + mu_I X_I^T + X_I mu_I^T + N_I) = int x x^T dV, the solid's moments
// integrated element by element without the hats (partition of unity); every node's central
// second moment N_I - mu_I mu_I^T positive definite, and |mu_I| below the node's reach.
template <int D>
void expectMomentIdentities(const MeshedBody<D>& body, double tolerance) {
  ASSERT_EQ(body.offset.size(), body.position.size());
  ASSERT_EQ(body.spread.size(), body.position.size());
  Vec<D> first = Vec<D>::Zero();
  Mat<D> second = Mat<D>::Zero();
  double worstOffset = 0;
  for (std::size_t i = 0; i < body.position.size(); ++i) {
    const Vec<D>& X = body.position[i];
    const Vec<D>& mu = body.offset[i];
    const double V = body.volume[i];
    first += V * (X + mu);
    second += V * (X * X.transpose() + mu * X.transpose() + X * mu.transpose() + body.spread[i]);
    const Mat<D> central = body.spread[i] - mu * mu.transpose();
    // positive definite: the leading principal minors (Sylvester)
    EXPECT_GT(central(0, 0), 0.0) << i;
    const double minor2 = central.template topLeftCorner<2, 2>().determinant();
    EXPECT_GT(minor2, 0.0) << i;
    EXPECT_GT(central.determinant(), 0.0) << i;
    worstOffset = std::max(worstOffset, mu.norm() / std::sqrt(body.spread[i].trace()));
  }
  const double scale = std::sqrt(body.secondMoment.trace() * body.measure);
  EXPECT_LT((first - body.firstMoment).norm(), tolerance * scale);
  EXPECT_LT((second - body.secondMoment).norm(), tolerance * body.secondMoment.norm());
  EXPECT_LT(worstOffset, 1.0);  // the hat's centroid lies within its spread
  EXPECT_GT(worstOffset, 0.1);  // surface nodes: the hat leans into the body
}

// The outward normal of a linear facet (not normalised).
Vec<2> normal(const MeshedBody<2>& body, const std::array<Index, 2>& f) {
  const Vec<2> a = body.position[f[1]] - body.position[f[0]];
  return Vec<2>(a.y(), -a.x());
}
Vec<3> normal(const MeshedBody<3>& body, const std::array<Index, 3>& f) {
  return (body.position[f[1]] - body.position[f[0]])
      .cross(body.position[f[2]] - body.position[f[0]]);
}
template <int D, std::size_t N>
Vec<D> centre(const MeshedBody<D>& body, const std::array<Index, N>& f) {
  Vec<D> c = Vec<D>::Zero();
  for (const Index i : f)
    c += body.position[i];
  return c / double(N);
}

// The count of facets of `surface` whose normal n satisfies pred(n, facet centre).
template <int D, class P>
std::size_t countFacets(const MeshedBody<D>& body, const std::string& surface, P pred) {
  const auto& facets = body.surfaces.at(surface).facets;
  return std::count_if(facets.begin(), facets.end(), [&](const std::array<Index, D>& f) {
    return pred(normal(body, f), centre(body, f));
  });
}

// The particles of a surface lie on the circle (cylinder) of `radius` around the z axis.
template <int D>
double maxRadiusError(const MeshedBody<D>& body, const std::string& surface, double radius) {
  double worst = 0;
  for (const Index i : body.surfaces.at(surface).nodes)
    worst = std::max(worst, std::abs(body.position[i].template head<2>().norm() - radius));
  return worst;
}

std::vector<Index> allParticles(std::size_t n) {
  std::vector<Index> all(n);
  std::iota(all.begin(), all.end(), 0);
  return all;
}

// The relative length error of N order-2 arcs on a full circle, and the area missing from a disc
// of radius r meshed with N order-2 arcs (see the top of the file).
double arcLengthDeficit(std::size_t n) {
  const double t = 2 * kPi / double(n);
  return std::pow(t, 4) / 960;
}
double discAreaDeficit(double r, std::size_t n) {
  const double t = 2 * kPi / double(n);
  return kPi * r * r * std::pow(t, 4) / 480;
}

// ----------------------------------------------------------------------------------------------
// 2D: the ring 1 <= r <= 2 (OpenCASCADE .geo).

constexpr double kRingArea = 3 * kPi;

// The ring's area error predicted from its facet counts: the outer disc loses, the bore's loss
// is area gained. Returns {prediction, scale}: scale (the two terms' magnitudes) sets the
// tolerance, as they cancel in part.
std::pair<double, double> ringAreaError(const MeshedBody<2>& body) {
  const double outer = discAreaDeficit(2, body.surfaces.at("outer").facets.size());
  const double bore = discAreaDeficit(1, body.surfaces.at("bore").facets.size());
  return {bore - outer, bore + outer};
}

void expectRingProperties(const MeshedBody<2>& body) {
  expectPartitionOfUnity(body);
  ASSERT_EQ(body.surfaces.size(), 2u);
  const auto& bore = body.surfaces.at("bore");
  const auto& outer = body.surfaces.at("outer");
  EXPECT_LT(maxRadiusError(body, "bore", 1.0), 1e-9);
  EXPECT_LT(maxRadiusError(body, "outer", 2.0), 1e-9);
  // The measures: within the brief's 1e-3, and equal to the order-2 prediction to 2 % of its
  // terms (the next order is t^2 ~ 0.4 % smaller, the quadrature error far below).
  EXPECT_LT(relative(body.measure, kRingArea), 1e-3);
  const auto [predicted, scale] = ringAreaError(body);
  EXPECT_NEAR(body.measure - kRingArea, predicted, 0.02 * scale);
  EXPECT_NEAR((2 * kPi - bore.measure) / (2 * kPi), arcLengthDeficit(bore.facets.size()),
              0.02 * arcLengthDeficit(bore.facets.size()));
  EXPECT_NEAR((4 * kPi - outer.measure) / (4 * kPi), arcLengthDeficit(outer.facets.size()),
              0.02 * arcLengthDeficit(outer.facets.size()));
  // Outward: along the radius on the outer circle, against it on the bore.
  EXPECT_EQ(countFacets(body, "outer", [](Vec<2> n, Vec<2> c) { return n.dot(c) > 0; }),
            outer.facets.size());
  EXPECT_EQ(countFacets(body, "bore", [](Vec<2> n, Vec<2> c) { return n.dot(c) < 0; }),
            bore.facets.size());
  // The physical surface "wall" holds every particle.
  EXPECT_EQ(body.volumes.at("wall"), allParticles(body.position.size()));
}

std::size_t cellsWithCorners(const MeshedBody<2>& body, Index corners) {
  std::size_t count = 0;
  for (std::size_t c = 0; c + 1 < body.cellStart.size(); ++c)
    count += body.cellStart[c + 1] - body.cellStart[c] == corners;
  return count;
}

TEST(GmshBody2D, RingAtSize16) {
  const auto body = meshBody<2>(data("ring.geo"), 1.0 / 16);
  const auto& bore = body.surfaces.at("bore");
  std::cout << "ring at size 1/16: " << body.position.size() << " particles, "
            << body.cellStart.size() - 1 << " triangles, area error "
            << relative(body.measure, kRingArea) << " (predicted "
            << ringAreaError(body).first / kRingArea << "), bore length error "
            << relative(bore.measure, 2 * kPi) << " (predicted "
            << arcLengthDeficit(bore.facets.size()) << ")\n";
  EXPECT_TRUE(body.curved);
  EXPECT_NEAR(body.exactMeasure, kRingArea, 1e-12 * kRingArea);
  // 16 elements through the wall: the size is respected (sizes in [1/32, 1/16]).
  EXPECT_GE(bore.facets.size(), std::size_t(2 * kPi * 16));
  EXPECT_LE(bore.facets.size(), std::size_t(2 * kPi * 32));
  EXPECT_LT(relative(bore.measure, 2 * kPi), 1e-4);
  expectRingProperties(body);
  EXPECT_EQ(cellsWithCorners(body, 3), body.cellStart.size() - 1);
}

// The ring's moments: the nodes' sum is the element-by-element integral, and that is the ring's
// (int x = 0, int x x^T = pi (r2^4 - r1^4) / 4 1) to the geometry's order.
TEST(GmshBody2D, RingMomentsOfTheHats) {
  for (const bool recombine : {false, true}) {
    MeshOptions options;
    options.recombine = recombine;
    const auto body = meshBody<2>(data("ring.geo"), 1.0 / 16, options);
    SCOPED_TRACE(recombine ? "quadrangles" : "triangles");
    expectMomentIdentities(body, 1e-12);
    const double inertia = kPi * (16.0 - 1.0) / 4;
    EXPECT_LT(body.firstMoment.norm(), 1e-12 * inertia);
    EXPECT_LT((body.secondMoment - inertia * Mat<2>::Identity()).norm(), 1e-3 * inertia);
  }
}

TEST(GmshBody2D, RingConvergesAtTheOrderOfItsGeometry) {
  const double sizes[] = {1.0 / 8, 1.0 / 16, 1.0 / 32};
  double area[3], bore[3];
  for (int k = 0; k < 3; ++k) {
    const auto body = meshBody<2>(data("ring.geo"), sizes[k]);
    area[k] = relative(body.measure, kRingArea);
    bore[k] = relative(body.surfaces.at("bore").measure, 2 * kPi);
    std::cout << "ring at size 1/" << 1 / sizes[k] << ": " << body.position.size()
              << " particles, area error " << area[k] << ", bore length error " << bore[k] << "\n";
  }
  std::cout << "orders: area " << std::log2(area[0] / area[1]) << ", "
            << std::log2(area[1] / area[2]) << "; bore " << std::log2(bore[0] / bore[1]) << ", "
            << std::log2(bore[1] / bore[2]) << "\n";
  // Curved geometry: at least h^3 (the order-2 theory gives h^4; linear geometry h^2).
  EXPECT_GT(std::log2(area[0] / area[1]), 3.0);
  EXPECT_GT(std::log2(area[1] / area[2]), 3.0);
  EXPECT_GT(std::log2(bore[0] / bore[1]), 3.0);
  EXPECT_GT(std::log2(bore[1] / bore[2]), 3.0);
}

TEST(GmshBody2D, RecombinedRingIsQuadrangles) {
  MeshOptions options;
  options.recombine = true;
  const auto body = meshBody<2>(data("ring.geo"), 1.0 / 16, options);
  const std::size_t cells = body.cellStart.size() - 1, quads = cellsWithCorners(body, 4);
  std::cout << "recombined ring: " << body.position.size() << " particles, " << quads << " of "
            << cells << " cells quadrangles, area error " << relative(body.measure, kRingArea)
            << "\n";
  // Blossom recombination may leave a triangle here and there: 95 % quadrangles at least.
  EXPECT_GE(quads, std::size_t(0.95 * double(cells)));
  EXPECT_EQ(quads + cellsWithCorners(body, 3), cells);
  expectRingProperties(body);
}

TEST(GmshBody2D, BuiltinKernelPlateWithHole) {
  const auto body = meshBody<2>(data("square_hole_builtin.geo"), 1.0 / 8);
  const double exact = 16 - kPi;
  std::cout << "plate with hole: area error " << relative(body.measure, exact) << "\n";
  EXPECT_TRUE(std::isnan(body.exactMeasure));  // no OpenCASCADE entities
  expectPartitionOfUnity(body);
  // The straight sides are exact; the hole (four quarter arcs) lacks its order-2 deficit.
  const std::size_t n = body.surfaces.at("bore").facets.size();
  EXPECT_NEAR(body.measure - exact, discAreaDeficit(1, n), 0.02 * discAreaDeficit(1, n));
  EXPECT_NEAR(body.surfaces.at("sides").measure, 16, 1e-12 * 16);
  EXPECT_LT(maxRadiusError(body, "bore", 1.0), 1e-9);
  EXPECT_EQ(countFacets(body, "sides", [](Vec<2> n, Vec<2> c) { return n.dot(c) > 0; }),
            body.surfaces.at("sides").facets.size());
  EXPECT_EQ(countFacets(body, "bore", [](Vec<2> n, Vec<2> c) { return n.dot(c) < 0; }), n);
  EXPECT_EQ(body.volumes.at("plate"), allParticles(body.position.size()));
}

// A first-order mesh made by `gmsh -2` (sizes 0.25 to 0.5) is taken as it is.
TEST(GmshBody2D, FirstOrderMshOnItsLinearGeometry) {
  const auto body = meshBody<2>(data("ring_linear.msh"), 0);
  EXPECT_FALSE(body.curved);
  EXPECT_TRUE(std::isnan(body.exactMeasure));
  expectPartitionOfUnity(body);
  EXPECT_LT(maxRadiusError(body, "bore", 1.0), 1e-9);
  EXPECT_LT(maxRadiusError(body, "outer", 2.0), 1e-9);
  // The polygon's area from its oriented boundary (shoelace over the outward facets) and its
  // perimeters: the linear geometry, exactly.
  double shoelace = 0;
  for (const char* name : {"bore", "outer"}) {
    const auto& surface = body.surfaces.at(name);
    double length = 0;
    for (const auto& f : surface.facets) {
      const Vec<2>& a = body.position[f[0]];
      const Vec<2>& b = body.position[f[1]];
      shoelace += 0.5 * (a.x() * b.y() - a.y() * b.x());
      length += (b - a).norm();
    }
    EXPECT_NEAR(surface.measure, length, 1e-12 * length) << name;
  }
  std::cout << "first-order msh: " << body.position.size() << " particles, area " << body.measure
            << " (3 pi " << kRingArea << ")\n";
  EXPECT_NEAR(body.measure, shoelace, 1e-12 * shoelace);
  EXPECT_EQ(body.volumes.at("wall"), allParticles(body.position.size()));
  // The moments on the linear geometry, independently: each cell a fan of triangles, whose
  // int x = A (v0 + v1 + v2) / 3 and int x x^T = A / 12 (sum v v^T + s s^T), s = v0 + v1 + v2.
  Vec<2> first = Vec<2>::Zero();
  Mat<2> second = Mat<2>::Zero();
  for (std::size_t c = 0; c + 1 < body.cellStart.size(); ++c)
    for (Index k = body.cellStart[c] + 1; k + 1 < body.cellStart[c + 1]; ++k) {
      const Vec<2>& v0 = body.position[body.cellNode[body.cellStart[c]]];
      const Vec<2>& v1 = body.position[body.cellNode[k]];
      const Vec<2>& v2 = body.position[body.cellNode[k + 1]];
      const Vec<2> a = v1 - v0, b = v2 - v0;
      const double A = std::abs(0.5 * (a.x() * b.y() - a.y() * b.x()));
      const Vec<2> s = v0 + v1 + v2;
      first += A / 3 * s;
      second +=
          A / 12 *
          (v0 * v0.transpose() + v1 * v1.transpose() + v2 * v2.transpose() + s * s.transpose());
    }
  EXPECT_LT((body.firstMoment - first).norm(), 1e-12 * second.norm());
  EXPECT_LT((body.secondMoment - second).norm(), 1e-12 * second.norm());
  expectMomentIdentities(body, 1e-12);
}

// ----------------------------------------------------------------------------------------------
// 3D. The order-2 prediction of a disc, applied to a cylinder of height H meshed with edges of
// length up to `size` along its circumference (t = size / r), bounds its volume and area errors
// once multiplied by 10: tetrahedra edges run up to ~1.5 size, and slanted edges see less
// curvature. A linear mesh would be off by t^2 / 24, 1e2 to 1e3 times more at these sizes.
double cylinderVolumeBound(double r, double height, double fraction, double size) {
  return 10 * fraction * height * kPi * r * r * std::pow(size / r, 4) / 480;
}
double cylinderAreaBound(double size, double r) {
  return 10 * std::pow(size / r, 4) / 960;  // relative
}

// A facet's normal points along (sign > 0) or against (sign < 0) the direction from the z axis
// through `axis`.
template <class F>
std::size_t countRadial(const MeshedBody<3>& body, const std::string& surface, Vec<2> axis, F f) {
  return countFacets(body, surface, [&](const Vec<3>& n, const Vec<3>& c) {
    return f(n.head<2>().dot(c.head<2>() - axis));
  });
}

TEST(GmshBody3D, BoxWithCylindricalHole) {
  const auto body = meshBody<3>(data("box_hole.geo"), 0.25);
  const double exact = 32 - 2 * kPi;
  const auto& bore = body.surfaces.at("bore");
  std::cout << "box with hole at 0.25: " << body.position.size() << " particles, volume error "
            << relative(body.measure, exact) << ", bore area error "
            << relative(bore.measure, 4 * kPi) << "\n";
  EXPECT_NEAR(body.exactMeasure, exact, 1e-12 * exact);
  expectPartitionOfUnity(body);
  EXPECT_LT(relative(body.measure, body.exactMeasure), 1e-3);
  EXPECT_LT(std::abs(body.measure - exact), cylinderVolumeBound(1, 2, 1, 0.25));
  EXPECT_LT(relative(bore.measure, 4 * kPi), cylinderAreaBound(0.25, 1));
  EXPECT_NEAR(body.surfaces.at("top").measure, 16 - kPi, cylinderVolumeBound(1, 1, 1, 0.25));
  double worst = 0;
  for (const Index i : bore.nodes)
    worst = std::max(worst, std::abs((body.position[i].head<2>() - Vec<2>(2, 2)).norm() - 1));
  EXPECT_LT(worst, 1e-9);
  // Outward: down at the bottom, up at the top, towards the axis in the hole.
  EXPECT_EQ(countFacets(body, "bottom", [](Vec<3> n, Vec<3>) { return n.z() < 0; }),
            body.surfaces.at("bottom").facets.size());
  EXPECT_EQ(countFacets(body, "top", [](Vec<3> n, Vec<3>) { return n.z() > 0; }),
            body.surfaces.at("top").facets.size());
  EXPECT_EQ(countRadial(body, "bore", Vec<2>(2, 2), [](double d) { return d < 0; }),
            bore.facets.size());
  EXPECT_EQ(body.volumes.at("block"), allParticles(body.position.size()));
  expectMomentIdentities(body, 1e-12);
}

TEST(GmshBody3D, QuarterRingInTwoLayers) {
  const auto body = meshBody<3>(data("quarter_ring.geo"), 0.125);
  const double exact = 0.75 * kPi;
  const auto& bore = body.surfaces.at("bore");
  const auto& outer = body.surfaces.at("outer");
  std::cout << "quarter ring at 0.125: " << body.position.size() << " particles, volume error "
            << relative(body.measure, exact) << ", bore area error "
            << relative(bore.measure, kPi / 2) << ", outer " << relative(outer.measure, kPi)
            << "\n";
  expectPartitionOfUnity(body);
  EXPECT_NEAR(body.exactMeasure, exact, 1e-12 * exact);
  EXPECT_LT(std::abs(body.measure - exact),
            cylinderVolumeBound(1, 1, 0.25, 0.125) + cylinderVolumeBound(2, 1, 0.25, 0.125));
  EXPECT_LT(relative(bore.measure, kPi / 2), cylinderAreaBound(0.125, 1));
  EXPECT_LT(relative(outer.measure, kPi), cylinderAreaBound(0.125, 2));
  EXPECT_LT(maxRadiusError(body, "bore", 1.0), 1e-9);
  EXPECT_LT(maxRadiusError(body, "outer", 2.0), 1e-9);
  EXPECT_EQ(countRadial(body, "bore", Vec<2>(0, 0), [](double d) { return d < 0; }),
            bore.facets.size());
  EXPECT_EQ(countRadial(body, "outer", Vec<2>(0, 0), [](double d) { return d > 0; }),
            outer.facets.size());
  // The two layers: each on its side of z = 0.5, sharing the interface's particles exactly.
  const auto& lower = body.volumes.at("lower");
  const auto& upper = body.volumes.at("upper");
  std::vector<Index> both, either, interface;
  std::set_intersection(lower.begin(), lower.end(), upper.begin(), upper.end(),
                        std::back_inserter(both));
  std::set_union(lower.begin(), lower.end(), upper.begin(), upper.end(),
                 std::back_inserter(either));
  for (std::size_t i = 0; i < body.position.size(); ++i)
    if (std::abs(body.position[i].z() - 0.5) < 1e-12) interface.push_back(Index(i));
  EXPECT_EQ(either, allParticles(body.position.size()));
  EXPECT_EQ(both, interface);
  EXPECT_GT(interface.size(), 100u);
  for (const Index i : lower)
    ASSERT_LE(body.position[i].z(), 0.5 + 1e-12);
  for (const Index i : upper)
    ASSERT_GE(body.position[i].z(), 0.5 - 1e-12);
}

TEST(GmshBody3D, VolumeConvergesAtTheOrderOfItsGeometry) {
  double error[2];
  const double sizes[] = {0.25, 0.125};
  for (int k = 0; k < 2; ++k) {
    const auto start = std::chrono::steady_clock::now();
    const auto body = meshBody<3>(data("box_hole.geo"), sizes[k]);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    error[k] = relative(body.measure, body.exactMeasure);
    std::cout << "box with hole at " << sizes[k] << ": " << body.position.size() << " particles, "
              << body.cellStart.size() - 1 << " tetrahedra, volume error " << error[k]
              << ", meshBody " << seconds << " s\n";
  }
  std::cout << "order " << std::log2(error[0] / error[1]) << "\n";
  EXPECT_GT(std::log2(error[0] / error[1]), 3.0);
}

// CAD files through OpenCASCADE: the same solids as the .geo files, without physical groups.
TEST(GmshBody3D, StepAndBrep) {
  const auto step = meshBody<3>(data("box_hole.step"), 0.25);
  EXPECT_NEAR(step.exactMeasure, 32 - 2 * kPi, 1e-12 * 32);
  EXPECT_LT(std::abs(step.measure - step.exactMeasure), cylinderVolumeBound(1, 2, 1, 0.25));
  expectPartitionOfUnity(step);
  const auto brep = meshBody<3>(data("quarter_ring.BREP"), 0.125);
  EXPECT_NEAR(brep.exactMeasure, 0.75 * kPi, 1e-12);
  EXPECT_LT(std::abs(brep.measure - brep.exactMeasure),
            cylinderVolumeBound(1, 1, 0.25, 0.125) + cylinderVolumeBound(2, 1, 0.25, 0.125));
  expectPartitionOfUnity(brep);
  // OpenCASCADE reads STEP in millimetres unless told the unit: this file says millimetres.
  MeshOptions metres;
  metres.cadUnit = "M";
  const auto inMetres = meshBody<3>(data("box_hole.step"), 0.25e-3, metres);
  EXPECT_NEAR(inMetres.exactMeasure, (32 - 2 * kPi) * 1e-9, 1e-12 * 32e-9);
  EXPECT_LT(std::abs(inMetres.measure - inMetres.exactMeasure),
            cylinderVolumeBound(1, 2, 1, 0.25) * 1e-9);
  std::cout << "step volume error " << relative(step.measure, step.exactMeasure)
            << ", brep volume error " << relative(brep.measure, brep.exactMeasure) << "; groups "
            << step.surfaces.size() + step.volumes.size() + brep.surfaces.size() +
                   brep.volumes.size()
            << "\n";
}

// The volume an ASCII STL file encloses: the divergence theorem on its triangles.
double stlVolume(const std::string& path) {
  std::ifstream in(path);
  std::string word;
  std::vector<Vec<3>> v;
  double six = 0;
  while (in >> word) {
    if (word != "vertex") continue;
    Vec<3> x;
    in >> x.x() >> x.y() >> x.z();
    v.push_back(x);
    if (v.size() == 3) {
      six += v[0].dot(v[1].cross(v[2]));
      v.clear();
    }
  }
  return std::abs(six) / 6;
}

TEST(GmshBody3D, ClosedStlOfFlatFacesExactly) {
  const std::string path = data("l_block.stl");
  const double enclosed = stlVolume(path);
  EXPECT_NEAR(enclosed, 3.0, 1e-12);  // the L of 2 x 1 x 1 and 1 x 1 x 1 boxes
  const auto body = meshBody<3>(path, 0.25);
  std::cout << "STL: " << body.position.size() << " particles, volume error "
            << relative(body.measure, enclosed) << "\n";
  EXPECT_NEAR(body.measure, enclosed, 1e-9 * enclosed);
  EXPECT_TRUE(std::isnan(body.exactMeasure));
  expectPartitionOfUnity(body);
  for (const auto& x : body.position) {  // remeshed on the STL's faces
    ASSERT_TRUE((x.array() >= -1e-12).all() && (x.array() <= 2 + 1e-12).all());
    ASSERT_FALSE(x.x() > 1 + 1e-12 && x.y() > 1 + 1e-12);
  }
  // Flat faces: the moments are the L's, [0, 2] x [0, 1] x [0, 1] and [0, 1] x [1, 2] x [0, 1].
  Vec<3> first = Vec<3>::Zero();
  Mat<3> second = Mat<3>::Zero();
  for (const auto& [lo, hi] :
       {std::pair{Vec<3>(0, 0, 0), Vec<3>(2, 1, 1)}, std::pair{Vec<3>(0, 1, 0), Vec<3>(1, 2, 1)}}) {
    const double V = (hi - lo).prod();
    const Vec<3> c = 0.5 * (lo + hi);
    first += V * c;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        second(i, j) +=
            i == j ? V * (lo[i] * lo[i] + lo[i] * hi[i] + hi[i] * hi[i]) / 3 : V * c[i] * c[j];
  }
  EXPECT_LT((body.firstMoment - first).norm(), 1e-9 * first.norm());
  EXPECT_LT((body.secondMoment - second).norm(), 1e-9 * second.norm());
  expectMomentIdentities(body, 1e-12);
}

// A curved part's STL (a cylinder of radius 1 and length 2 in 432 triangles about 0.5 long,
// written by gmsh) loads at spacings coarser and finer than its triangles, and its volume
// converges to the one its triangles enclose at second order (the remeshed surface's chords).
// With the order-2 nodes projected onto the triangles' patches, three of these four spacings
// gave inverted elements.
TEST(GmshBody3D, ClosedStlOfACurvedPartAtAnySpacing) {
  const std::string path = data("cylinder.stl");
  const double enclosed = stlVolume(path);
  EXPECT_NEAR(enclosed, 6.1089, 1e-4);  // 2 pi less the facets' chords
  std::vector<double> deficit;
  for (const double size : {1.0, 0.5, 0.25, 0.15}) {
    const auto body = meshBody<3>(path, size);
    expectPartitionOfUnity(body);
    for (const auto& x : body.position) {
      ASSERT_LE(x.head<2>().norm(), 1 + 1e-9);
      ASSERT_TRUE(x.z() >= -1e-12 && x.z() <= 2 + 1e-12);
    }
    deficit.push_back(1 - body.measure / enclosed);
    std::cout << "cylinder STL at size " << size << ": " << body.position.size()
              << " particles, volume deficit " << deficit.back() << "\n";
  }
  for (std::size_t k = 0; k < deficit.size(); ++k) {
    EXPECT_GT(deficit[k], 0.0);  // linear tetrahedra inside the triangles
    if (k > 0) EXPECT_LT(deficit[k], deficit[k - 1]);
  }
  EXPECT_LT(deficit.back(), 0.004);  // 0.27 % at size 0.15 (1.7 % at 1)
}

// ----------------------------------------------------------------------------------------------
// gmsh's side effects on the process and the disk.

std::set<std::filesystem::path> listing(const std::filesystem::path& dir) {
  std::set<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(dir))
    files.insert(entry.path());
  return files;
}

// (Not checked: the FLTK preference files Debian's gmsh rewrites at initialisation, see
// GmshBody.hpp.)
TEST(GmshBodyProcess, LeavesThreadsLocaleAndDirectoriesAlone) {
  const std::string locale = std::setlocale(LC_ALL, nullptr);
  const auto cwd = std::filesystem::current_path();
  const auto here = listing(cwd), there = listing(TLSPH_GEOMETRY_DATA);
#ifdef _OPENMP
  omp_set_num_threads(3);
#endif
  meshBody<3>(data("quarter_ring.geo"), 0.5);
  EXPECT_THROW(meshBody<2>(data("garbage.geo"), 0.5), GeometryError);
#ifdef _OPENMP
  EXPECT_EQ(omp_get_max_threads(), 3);  // gmsh::initialize sets 1
#endif
  EXPECT_EQ(std::setlocale(LC_ALL, nullptr), locale);
  EXPECT_EQ(std::filesystem::current_path(), cwd);
  EXPECT_EQ(listing(cwd), here);
  EXPECT_EQ(listing(TLSPH_GEOMETRY_DATA), there);
}

// One call at a time: a call while another runs is refused, not run on gmsh's shared state.
TEST(GmshBodyProcess, ConcurrentCallsAreRefused) {
  std::atomic<bool> done{false};
  std::atomic<int> refused{0};
  auto refusal = [&](const GeometryError& e) {
    if (std::string(e.what()).find("gmsh is in use by another meshBody call") == std::string::npos)
      ADD_FAILURE() << e.what();
    ++refused;
  };
  std::thread worker([&] {
    try {
      const auto body = meshBody<3>(data("box_hole.geo"), 0.2);
      EXPECT_GT(body.position.size(), 1000u);
    } catch (const GeometryError& e) {
      refusal(e);
    }
    done = true;
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(50));  // the worker first, mostly
  while (!done) {
    try {
      meshBody<2>(data("ring.geo"), 1.0);
    } catch (const GeometryError& e) {
      refusal(e);
    }
  }
  worker.join();
  EXPECT_GE(refused.load(), 1);
}

// ----------------------------------------------------------------------------------------------
// Bad input: each error names the file and the reason.

TEST(GmshBodyErrors, FileProblems) {
  expectMessage(errorOf([] { meshBody<2>(data("missing.geo"), 0.5); }),
                {"missing.geo", "cannot read the file", "does not exist"});
  expectMessage(errorOf([] { meshBody<2>(data("garbage.geo"), 0.5); }),
                {"garbage.geo", "gmsh cannot read the file", "syntax error"});
  expectMessage(errorOf([] { meshBody<3>(data("garbage.step"), 0.5); }),
                {"garbage.step", "gmsh cannot read the file", "Could not read"});
  expectMessage(errorOf([] { meshBody<2>(data("ring.iges"), 0.5); }),
                {"ring.iges", "unknown file kind '.iges'", ".geo, .step, .stp, .brep, .stl, .msh"});
  expectMessage(errorOf([] { meshBody<3>(data("l_block.Stl"), 0.5); }),
                {"l_block.Stl", ".stl or .STL only"});
  expectMessage(errorOf([] { meshBody<2>(data("ring.geo"), 0); }),
                {"ring.geo", "mesh size must be positive"});
  MeshOptions crashing;
  crashing.algorithm = 8;
  expectMessage(errorOf([&] { meshBody<2>(data("ring.geo"), 0.5, crashing); }),
                {"ring.geo", "Mesh.Algorithm 8", "crashes gmsh"});
}

TEST(GmshBodyErrors, NotASolidOfTheDimension) {
  for (auto message : {errorOf([] { meshBody<2>(data("curves_only.geo"), 0.5); }),
                       errorOf([] { meshBody<3>(data("curves_only.geo"), 0.5); })})
    expectMessage(message, {"curves_only.geo", "empty solid"});
  expectMessage(errorOf([] { meshBody<3>(data("ring.geo"), 0.5); }),
                {"ring.geo", "a 2D model", "3D body"});
  expectMessage(errorOf([] { meshBody<2>(data("box_hole.geo"), 0.5); }),
                {"box_hole.geo", "a 3D model", "2D body"});
  expectMessage(errorOf([] { meshBody<2>(data("ring_z1.geo"), 0.5); }),
                {"ring_z1.geo", "not in the z = 0 plane"});
  expectMessage(errorOf([] { meshBody<2>(data("l_block.stl"), 0.5); }),
                {"l_block.stl", "cannot be a 2D body"});
}

TEST(GmshBodyErrors, BadSurfacesAndElements) {
  expectMessage(errorOf([] { meshBody<3>(data("l_block_open.stl"), 0.5); }),
                {"l_block_open.stl", "surface is not closed", "3 triangle edges"});
  expectMessage(errorOf([] { meshBody<3>(data("two_cubes_overlapping.stl"), 0.5); }),
                {"two_cubes_overlapping.stl", "meshing failed", "self-intersecting",
                 "segment-facet intersection"});
  // Three counter-clockwise triangles and one clockwise in one surface.
  expectMessage(errorOf([] { meshBody<2>(data("square_one_inverted.msh"), 0); }),
                {"square_one_inverted.msh", "inverted element"});
}

}  // namespace
