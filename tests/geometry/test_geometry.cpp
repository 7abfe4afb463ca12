// Geometry: shapes are closed and exact, lattice fills give every cell centre inside a union of
// shapes once, x fastest (a scene then numbers them with its longest axis slowest), and degenerate
// input is rejected with a message naming the problem.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include "geometry/Lattice.hpp"
#include "geometry/LatticeFill.hpp"
#include "geometry/LocalityOrder.hpp"

using namespace tlsph;

namespace {

constexpr double kPi = std::numbers::pi;

Vec<2> v2(double x, double y) {
  return Vec<2>(x, y);
}
Vec<3> v3(double x, double y, double z) {
  return Vec<3>(x, y, z);
}

// The L of [0, 0.6] x [0, 0.2] and [0, 0.2] x [0.2, 0.5], counter-clockwise.
std::vector<Vec<2>> lShape() {
  return {v2(0, 0), v2(0.6, 0), v2(0.6, 0.2), v2(0.2, 0.2), v2(0.2, 0.5), v2(0, 0.5)};
}

std::vector<Vec<2>> reversed(std::vector<Vec<2>> v) {
  std::reverse(v.begin(), v.end());
  return v;
}

// The lattice order of fillLattice: compare z, then y, then x.
template <int D>
bool latticeLess(const Vec<D>& a, const Vec<D>& b) {
  for (int k = D - 1; k >= 0; --k)
    if (a[k] != b[k]) return a[k] < b[k];
  return false;
}

// Strictly increasing in lattice order: deterministic order and no point twice.
template <int D>
void expectStrictlyOrdered(const std::vector<Vec<D>>& points) {
  for (std::size_t i = 1; i < points.size(); ++i)
    ASSERT_TRUE(latticeLess<D>(points[i - 1], points[i])) << "at point " << i;
}

template <int D>
void expectSamePoints(const std::vector<Vec<D>>& actual, const std::vector<Vec<D>>& expected) {
  ASSERT_EQ(actual.size(), expected.size());
  for (std::size_t i = 0; i < actual.size(); ++i)
    ASSERT_TRUE(actual[i] == expected[i])
        << "point " << i << ": " << actual[i].transpose() << " vs " << expected[i].transpose();
}

// Every lattice point with -m <= n < m that lies in a shape, x fastest: tested at
// origin + (n + 1/2) dx as evaluated in double, placed at cell n of latticeAxes' grid.
template <int D>
std::vector<Vec<D>> bruteForceFill(const std::vector<Shape<D>>& shapes, double dx,
                                   const Vec<D>& origin, int m) {
  const auto axes = latticeAxes<D>(shapes, dx, origin);
  std::vector<Vec<D>> points;
  std::array<int, D> n;
  n.fill(-m);
  while (n[D - 1] < m) {
    Vec<D> tested, x;
    for (int a = 0; a < D; ++a) {
      tested[a] = origin[a] + (n[a] + 0.5) * dx;
      x[a] = axes[a].coordinate(n[a]);
    }
    if (std::any_of(shapes.begin(), shapes.end(),
                    [&](const auto& s) { return contains(s, tested); }))
      points.push_back(x);
    for (int a = 0; a < D && ++n[a] == m && a < D - 1; ++a)
      n[a] = -m;
  }
  return points;
}

template <int D>
void expectAllInside(const Shape<D>& shape, const std::vector<Vec<D>>& points) {
  const auto box = bounds(shape);
  ASSERT_TRUE(box.has_value());
  for (const auto& x : points) {
    ASSERT_TRUE(contains(shape, x)) << x.transpose();
    ASSERT_TRUE(box->contains(x)) << x.transpose();
  }
}

// The cells cut by the boundary form a layer of volume about surface * dx; their errors largely
// cancel, so a quarter of that layer still catches a lost or doubled half-layer.
template <int D>
void expectVolume(const Shape<D>& shape, double dx, double volume, double surface) {
  const auto points = fillLattice<D>({shape}, dx);
  expectAllInside<D>(shape, points);
  const double measured = static_cast<double>(points.size()) * std::pow(dx, D);
  EXPECT_LT(std::abs(measured - volume) / volume, 0.25 * surface * dx / volume)
      << shapeName(shape) << ": " << points.size() << " points, volume " << measured << " vs "
      << volume;
}

template <class AnyShape>
void expectRejected(const AnyShape& shape, const std::string& expected) {
  try {
    validate(shape);
    ADD_FAILURE() << "accepted, expected \"" << expected << "\"";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(expected), std::string::npos)
        << "message \"" << e.what() << "\" lacks \"" << expected << "\"";
  }
}

template <class Function>
std::string lengthErrorOf(Function&& f) {
  try {
    f();
  } catch (const std::length_error& e) {
    return e.what();
  }
  return "(no std::length_error)";
}

// 1. Boxes aligned with cell faces hold exactly their cells, at the cell centres.

TEST(LatticeFill, BoxGivesItsCellCentres3D) {
  const double dx = 0.0125;
  const auto points = fillLattice<3>({Box<3>{.lower = v3(0, 0, 0), .upper = v3(1, 0.1, 0.1)}}, dx);
  EXPECT_EQ(points.size(), 80u * 8u * 8u);
  expectSamePoints<3>(points, cellCentredLattice<3>(Vec<3>::Zero(), {80, 8, 8}, dx));
}

TEST(LatticeFill, BoxGivesItsCellCentres2D) {
  const double dx = 0.0125;
  const auto points = fillLattice<2>({Box<2>{.lower = v2(0, 0), .upper = v2(1, 0.1)}}, dx);
  EXPECT_EQ(points.size(), 80u * 8u);
  expectSamePoints<2>(points, cellCentredLattice<2>(Vec<2>::Zero(), {80, 8}, dx));
}

TEST(LatticeFill, BoxOffTheOriginUsesTheShiftedLattice) {
  // Lattice origin (0.1, -0.3): the box [-0.2, 0.4] x [-0.5, 0.1] spans 12 x 12 cells of 0.05.
  const double dx = 0.05;
  const Vec<2> origin = v2(0.1, -0.3);
  const auto points =
      fillLattice<2>({Box<2>{.lower = v2(-0.2, -0.5), .upper = v2(0.4, 0.1)}}, dx, origin);
  EXPECT_EQ(points.size(), 12u * 12u);
  for (const auto& x : points)
    for (int a = 0; a < 2; ++a) {
      const double cells = (x[a] - origin[a]) / dx - 0.5;
      EXPECT_NEAR(cells, std::round(cells), 1e-9) << x.transpose();
    }
}

// 2. Curved shapes: count * dx^D approximates the analytic measure within the boundary layer.

TEST(LatticeFill, DiscAreaAndCylinderIn2DIsTheSameDisc) {
  const double r = 0.25, dx = 0.01;
  const Vec<2> c = v2(0.3, -0.2);
  expectVolume<2>(Ball<2>{.centre = c, .radius = r}, dx, kPi * r * r, 2 * kPi * r);
  expectSamePoints<2>(fillLattice<2>({Cylinder<2>{.start = c, .end = c, .radius = r}}, dx),
                      fillLattice<2>({Ball<2>{.centre = c, .radius = r}}, dx));
}

TEST(LatticeFill, SphereVolume) {
  const double r = 0.2;
  expectVolume<3>(Ball<3>{.centre = v3(0.01, 0.02, -0.03), .radius = r}, 0.01,
                  4.0 / 3.0 * kPi * r * r * r, 4 * kPi * r * r);
}

TEST(LatticeFill, TiltedCylinderVolume) {
  const Vec<3> start = v3(0.1, 0.0, -0.1), end = v3(0.4, 0.2, 0.3);
  const double r = 0.08, length = (end - start).norm();
  expectVolume<3>(Cylinder<3>{.start = start, .end = end, .radius = r}, 0.01, kPi * r * r * length,
                  2 * kPi * r * length + 2 * kPi * r * r);
}

TEST(LatticeFill, CylinderBoundsAreTight) {
  const auto box = Cylinder<3>{.start = v3(1, 2, 3), .end = v3(1, 2, 5), .radius = 0.5}.bounds();
  EXPECT_TRUE(box.min() == v3(0.5, 1.5, 3));
  EXPECT_TRUE(box.max() == v3(1.5, 2.5, 5));
}

// Filling visits only the shapes' bounding boxes; it must find exactly what testing every
// lattice point finds, for indices of either sign and an arbitrary origin.
TEST(LatticeFill, MatchesTestingEveryLatticePoint) {
  const double dx = 0.02;
  const Vec<3> origin = v3(0.0031, -0.0047, 0.0013);
  const std::vector<Shape<3>> shapes = {
      Cylinder<3>{.start = v3(-0.3, -0.2, 0.1), .end = v3(0.4, 0.3, -0.5), .radius = 0.12},
      Ball<3>{.centre = v3(0.5, -0.5, 0.2), .radius = 0.2},
      Polygon<3>{.vertices = reversed(lShape()), .axis = 1, .from = -0.7, .to = -0.2},
      Box<3>{.lower = v3(-0.7, 0.3, -0.1), .upper = v3(-0.1, 0.7, 0.33)}};
  const auto points = fillLattice<3>(shapes, dx, origin);
  expectSamePoints<3>(points, bruteForceFill<3>(shapes, dx, origin, 40));
  EXPECT_GT(points.size(), 10000u);
}

// A face through cell centres: Cook's membrane's top edge y = 0.044 + x/3 holds 8, 16, 32
// centres at dx = 0.002, 0.001, 0.0005. Whether they are particles is decided where the fill
// always decided (origin + (n + 1/2) dx in double), not at the exact grid's coordinates, so
// the exact grid changes no scene's particle set.
TEST(LatticeFill, PointsOnAFaceKeepTheDecisionOfTheFormula) {
  const std::vector<Shape<2>> cook = {
      Polygon<2>{.vertices = {v2(0, 0), v2(0.048, 0.044), v2(0.048, 0.060), v2(0, 0.044)}}};
  for (const double dx : {0.002, 0.001, 0.0005}) {
    const auto points = fillLattice<2>(cook, dx);
    expectSamePoints<2>(points, bruteForceFill<2>(cook, dx, Vec<2>::Zero(), 130));
    int onEdge = 0;
    for (int i = 0; (i + 0.5) * dx < 0.048; ++i)
      for (int j = 0; (j + 0.5) * dx < 0.060; ++j)
        onEdge += std::abs((j + 0.5) * dx - 0.044 - (i + 0.5) * dx / 3.0) < 1e-12;
    EXPECT_EQ(onEdge, static_cast<int>(std::lround(0.016 / dx))) << "dx " << dx;
  }
}

// 2b. The coordinates are exact on one binary grid (LatticeGrid.hpp): within a hair of
// origin + (n + 1/2) dx, every offset between two points a whole number of one spacing (the
// same in every body and on every axis), and a lattice about zero mirror-symmetric to the bit.

TEST(LatticeFill, CoordinatesAreCloseToTheFormula) {
  const double dx = 0.01;
  const Vec<3> origin = v3(0.0031, -0.0047, 0.0013);
  const std::vector<Shape<3>> shapes = {
      Box<3>{.lower = v3(-0.3, -0.05, -0.05), .upper = v3(0.7, 0.05, 0.05)}};
  const auto points = fillLattice<3>(shapes, dx, origin);
  ASSERT_EQ(points.size(), 100u * 10u * 10u);
  // The grid's step q = 2^(ilogb(reach) - 50) = 2^-51 here: the spacing is within q of dx and
  // the origin within q/2, so cell n moves by at most (|n| + 1) q from the formula.
  const double q = 0x1p-51;
  double worst = 0.0;
  for (const auto& x : points)
    for (int a = 0; a < 3; ++a) {
      const double n = std::round((x[a] - origin[a]) / dx - 0.5);
      const double moved = std::abs(x[a] - (origin[a] + (n + 0.5) * dx));
      EXPECT_LE(moved, (std::abs(n) + 2.0) * q) << x.transpose();
      worst = std::max(worst, moved);
    }
  std::cout << "largest move from the formula: " << worst << " (" << worst / dx << " dx)\n";
}

TEST(LatticeFill, OffsetsAreWholeSpacingsInEveryBodyAndAxis) {
  const double dx = 0.01;
  const std::vector<Shape<3>> shapes = {
      Box<3>{.lower = v3(0.1, 0.0, 0.0), .upper = v3(0.35, 0.05, 0.03)},
      Ball<3>{.centre = v3(-0.4, 0.2, 0.1), .radius = 0.06}};
  const auto axes = latticeAxes<3>(shapes, dx);
  const double spacing = axes[0].spacing();
  EXPECT_EQ(axes[1].spacing(), spacing);
  EXPECT_EQ(axes[2].spacing(), spacing);
  EXPECT_LE(std::abs(spacing - dx), axes[0].quantum);
  const auto points = fillLattice<3>(shapes, dx);
  ASSERT_GT(points.size(), 1000u);
  // Against a point of the box, every point's offset is exact: m spacings, m an integer.
  const Vec<3> anchor = points.front();
  for (const auto& x : points)
    for (int a = 0; a < 3; ++a) {
      const double offset = x[a] - anchor[a];
      const double m = std::round(offset / spacing);
      ASSERT_EQ(offset, m * spacing) << x.transpose() << " axis " << a;
    }
}

TEST(LatticeFill, LatticeAboutZeroIsMirrorSymmetric) {
  const double dx = 0.0125;
  const auto points = fillLattice<2>({Box<2>{.lower = v2(-0.3, -0.1), .upper = v2(0.3, 0.1)}}, dx);
  ASSERT_EQ(points.size(), 48u * 16u);
  std::vector<Vec<2>> mirrored;
  for (const auto& x : points)
    mirrored.push_back(-x);
  std::sort(mirrored.begin(), mirrored.end(), latticeLess<2>);
  expectSamePoints<2>(points, mirrored);
}

TEST(LatticeFill, RejectsALatticeReachingTooFarFromZero) {
  const std::vector<Shape<2>> far = {Box<2>{.lower = v2(3e4, 0), .upper = v2(3e4 + 1, 1)}};
  try {
    fillLattice<2>(far, 0.01);
    ADD_FAILURE() << "a box 3e6 spacings from zero was filled";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("shape 0 reaches more than 2^20 lattice spacings (dx "
                                         "0.01) from zero along x"),
              std::string::npos)
        << e.what();
  }
  EXPECT_EQ(fillLattice<2>(far, 0.05).size(), 20u * 20u);  // 6e5 spacings: within reach
  EXPECT_THROW(cellCentredLattice<2>(v2(3e4, 0), {2, 2}, 0.01), std::invalid_argument);
}

// 3. Polygons: non-convex, either orientation, extruded along any axis.

TEST(LatticeFill, LShapedPolygonEqualsItsTwoBoxes) {
  const double dx = 0.05;
  const auto boxes = fillLattice<2>({Box<2>{.lower = v2(0, 0), .upper = v2(0.6, 0.2)},
                                     Box<2>{.lower = v2(0, 0.2), .upper = v2(0.2, 0.5)}},
                                    dx);
  EXPECT_EQ(boxes.size(), 12u * 4u + 4u * 6u);
  expectSamePoints<2>(fillLattice<2>({Polygon<2>{.vertices = lShape()}}, dx), boxes);
  expectSamePoints<2>(fillLattice<2>({Polygon<2>{.vertices = reversed(lShape())}}, dx), boxes);
}

TEST(LatticeFill, PrismEqualsTheExtrudedPolygon) {
  const double dx = 0.05;
  const std::size_t planar = 12 * 4 + 4 * 6, layers = 6;  // extruded over [0, 0.3]
  // Axis 0: polygon coordinates are (y, z).
  const auto alongX =
      fillLattice<3>({Polygon<3>{.vertices = lShape(), .axis = 0, .from = 0.0, .to = 0.3}}, dx);
  EXPECT_EQ(alongX.size(), planar * layers);
  expectSamePoints<3>(alongX,
                      fillLattice<3>({Box<3>{.lower = v3(0, 0, 0), .upper = v3(0.3, 0.6, 0.2)},
                                      Box<3>{.lower = v3(0, 0, 0.2), .upper = v3(0.3, 0.2, 0.5)}},
                                     dx));
  // Axis 1: polygon coordinates are (x, z); clockwise vertices.
  const auto alongY = fillLattice<3>(
      {Polygon<3>{.vertices = reversed(lShape()), .axis = 1, .from = 0.0, .to = 0.3}}, dx);
  expectSamePoints<3>(alongY,
                      fillLattice<3>({Box<3>{.lower = v3(0, 0, 0), .upper = v3(0.6, 0.3, 0.2)},
                                      Box<3>{.lower = v3(0, 0, 0.2), .upper = v3(0.2, 0.3, 0.5)}},
                                     dx));
  // Axis 2: polygon coordinates are (x, y).
  const auto alongZ =
      fillLattice<3>({Polygon<3>{.vertices = lShape(), .axis = 2, .from = 0.0, .to = 0.3}}, dx);
  expectSamePoints<3>(alongZ,
                      fillLattice<3>({Box<3>{.lower = v3(0, 0, 0), .upper = v3(0.6, 0.2, 0.3)},
                                      Box<3>{.lower = v3(0, 0.2, 0), .upper = v3(0.2, 0.5, 0.3)}},
                                     dx));
}

TEST(Shape, PolygonAreaHasTheOrientationsSign) {
  EXPECT_NEAR(polygon::signedArea(lShape()), 0.6 * 0.2 + 0.2 * 0.3, 1e-15);
  EXPECT_NEAR(polygon::signedArea(reversed(lShape())), -(0.6 * 0.2 + 0.2 * 0.3), 1e-15);
}

TEST(Shape, PolygonAndBoxAreClosed) {
  // dx = 1/64 makes every coordinate exact: the 64 points on the hypotenuse x + y = 1 belong to
  // the triangle, in either orientation, giving 64 + 63 + ... + 1 points.
  const double dx = 1.0 / 64.0;
  const std::vector<Vec<2>> triangle = {v2(0, 0), v2(1, 0), v2(0, 1)};
  EXPECT_EQ(fillLattice<2>({Polygon<2>{.vertices = triangle}}, dx).size(), 64u * 65u / 2u);
  EXPECT_EQ(fillLattice<2>({Polygon<2>{.vertices = reversed(triangle)}}, dx).size(),
            64u * 65u / 2u);
  const Polygon<2> l{.vertices = lShape()};
  EXPECT_TRUE(l.contains(v2(0.2, 0.5)));   // vertex
  EXPECT_TRUE(l.contains(v2(0.4, 0.2)));   // on an edge
  EXPECT_TRUE(l.contains(v2(0.1, 0.2)));   // interior, level with a vertex
  EXPECT_FALSE(l.contains(v2(0.4, 0.3)));  // in the notch
  EXPECT_FALSE(l.contains(v2(-0.1, 0.2)));
  const Box<3> box{.lower = v3(0, 0, 0), .upper = v3(1, 2, 3)};
  EXPECT_TRUE(box.contains(v3(1, 2, 3)));
  EXPECT_TRUE(box.contains(v3(0, 1, 3)));
  EXPECT_FALSE(box.contains(v3(0, 2.0000001, 3)));
}

// 4. A union gives each lattice point once.

TEST(LatticeFill, UnionOfOverlappingBoxesHasNoDuplicates) {
  const double dx = 0.05;
  const std::vector<Shape<2>> shapes = {Box<2>{.lower = v2(0, 0), .upper = v2(0.5, 0.5)},
                                        Box<2>{.lower = v2(0.3, 0.2), .upper = v2(0.8, 0.6)}};
  const auto points = fillLattice<2>(shapes, dx);
  EXPECT_EQ(points.size(), 100u + 80u - 24u);  // inclusion-exclusion
  expectStrictlyOrdered<2>(points);
  expectSamePoints<2>(points, bruteForceFill<2>(shapes, dx, Vec<2>::Zero(), 20));

  const std::vector<Shape<3>> balls = {Ball<3>{.centre = v3(0, 0, 0), .radius = 0.3},
                                       Ball<3>{.centre = v3(0.2, 0.1, 0), .radius = 0.3},
                                       Ball<3>{.centre = v3(0.2, 0.1, 0), .radius = 0.2}};
  const auto blob = fillLattice<3>(balls, dx);
  expectStrictlyOrdered<3>(blob);
  expectSamePoints<3>(blob, bruteForceFill<3>(balls, dx, Vec<3>::Zero(), 12));
}

// 5. Half-spaces select particles of a region but cannot be filled.

TEST(PointSets, HalfSpaceSelectsTheSideTheNormalPointsTo) {
  const auto points = cellCentredLattice<3>(Vec<3>::Zero(), {10, 10, 10}, 0.1);
  const Shape<3> left = HalfSpace<3>{.point = v3(0.5, 7, -3), .normal = v3(-2, 0, 0)};
  const auto chosen = select<3>(left, points);
  ASSERT_EQ(chosen.size(), 500u);
  EXPECT_TRUE(std::is_sorted(chosen.begin(), chosen.end()));
  std::vector<bool> isChosen(points.size(), false);
  for (Index i : chosen)
    isChosen[i] = true;
  for (std::size_t i = 0; i < points.size(); ++i)
    EXPECT_EQ(isChosen[i], points[i].x() < 0.5) << points[i].transpose();

  // A tilted plane through the lattice: exactly the points on the normal's side.
  const Shape<3> tilted = HalfSpace<3>{.point = v3(0.5, 0.5, 0.5), .normal = v3(1, 2, -0.5)};
  const auto above = select<3>(tilted, points);
  std::size_t expected = 0;
  for (const auto& x : points)
    expected += (x - v3(0.5, 0.5, 0.5)).dot(v3(1, 2, -0.5)) >= 0;
  EXPECT_EQ(above.size(), expected);
  for (Index i : above)
    EXPECT_GE((points[i] - v3(0.5, 0.5, 0.5)).dot(v3(1, 2, -0.5)), 0.0);
  EXPECT_FALSE(bounds(tilted).has_value());
}

TEST(LatticeFill, RejectsHalfSpaces) {
  const HalfSpace<2> half{.point = v2(0, 0), .normal = v2(0, 1)};
  EXPECT_THROW(fillLattice<2>({half}, 0.1), std::invalid_argument);
  try {
    fillLattice<2>({Box<2>{.lower = v2(0, 0), .upper = v2(1, 1)}, half}, 0.1);
    ADD_FAILURE() << "a half-space was filled";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("shape 1 (half-space) is unbounded"), std::string::npos)
        << e.what();
  }
}

TEST(PointSets, BoundingBoxOfPoints) {
  const auto box = boundingBox<2>({v2(1, -2), v2(-3, 4), v2(0, 0)});
  EXPECT_TRUE(box.min() == v2(-3, -2));
  EXPECT_TRUE(box.max() == v2(1, 4));
  EXPECT_TRUE(boundingBox<3>({}).isEmpty());
}

// 6. Degenerate input is rejected, naming the problem.

TEST(Shape, ValidateRejectsDegenerateShapes) {
  expectRejected(Box<3>{.lower = v3(0, 0, 0), .upper = v3(1, 0, 1)},
                 "box: upper <= lower on axis y (lower 0, upper 0)");
  expectRejected(Box<2>{.lower = v2(0, 0), .upper = v2(-1, 1)}, "on axis x");
  expectRejected(Box<2>{.lower = v2(0, 0), .upper = v2(NAN, 1)}, "box: corners must be finite");
  expectRejected(Cylinder<3>{.start = v3(0, 0, 0), .end = v3(0, 0, 1), .radius = 0.0},
                 "cylinder: radius must be positive");
  expectRejected(Cylinder<3>{.start = v3(1, 2, 3), .end = v3(1, 2, 3), .radius = 1.0},
                 "cylinder: start and end coincide");
  expectRejected(Cylinder<2>{.start = v2(0, 0), .end = v2(0, 0), .radius = -1.0},
                 "radius must be positive");
  expectRejected(Ball<3>{.centre = v3(0, 0, 0), .radius = -0.5}, "ball: radius must be positive");
  expectRejected(Polygon<2>{.vertices = {v2(0, 0), v2(1, 0)}},
                 "polygon: needs at least 3 vertices, got 2");
  expectRejected(Polygon<2>{.vertices = {v2(0, 0), v2(0.1, 0.1), v2(0.3, 0.3)}},
                 "polygon: zero area");
  expectRejected(Polygon<2>{.vertices = {v2(0, 0), v2(0.3, 0.3), v2(0.1, 0.1), v2(0.2, 0.2)}},
                 "polygon: zero area");
  expectRejected(Polygon<2>{.vertices = {v2(0, 0), v2(1, 1), v2(1, 0), v2(0, 1)}},
                 "polygon: edges 0 and 2 intersect");
  // Two squares touching at a corner: not simple.
  expectRejected(Polygon<2>{.vertices = {v2(0, 0), v2(1, 0), v2(1, 1), v2(2, 1), v2(2, 2), v2(1, 2),
                                         v2(1, 1), v2(0, 1)}},
                 "intersect");
  // An edge folding back along its predecessor.
  expectRejected(Polygon<2>{.vertices = {v2(0, 0), v2(2, 0), v2(2, 2), v2(2, 1)}},
                 "edges 1 and 2 intersect");
  expectRejected(Polygon<2>{.vertices = {v2(0, 0), v2(1, 0), v2(1, 0), v2(0, 1)}},
                 "vertices 1 and 2 coincide");
  expectRejected(Polygon<3>{.vertices = lShape(), .axis = 2, .from = 1.0, .to = 1.0},
                 "polygon: extrusion needs from < to along z");
  expectRejected(Polygon<3>{.vertices = lShape(), .axis = 3, .from = 0.0, .to = 1.0},
                 "extrusion axis must be 0, 1 or 2");
  expectRejected(HalfSpace<3>{.point = v3(1, 1, 1), .normal = v3(0, 0, 0)},
                 "half-space: normal is zero");

  // Variants forward to the same checks.
  expectRejected(Shape<2>{Ball<2>{.centre = v2(0, 0), .radius = 0.0}}, "ball: radius");

  // Valid shapes pass, including a polygon with a straight-through (collinear) vertex.
  EXPECT_NO_THROW(validate(Polygon<2>{.vertices = {v2(0, 0), v2(1, 0), v2(2, 0), v2(1, 1)}}));
  EXPECT_NO_THROW(validate(Polygon<3>{.vertices = lShape(), .axis = 0, .from = 0, .to = 1}));
  EXPECT_NO_THROW(validate(Cylinder<2>{.start = v2(0, 0), .end = v2(0, 0), .radius = 1}));
  EXPECT_NO_THROW(validate(HalfSpace<2>{.point = v2(0, 0), .normal = v2(0, 1e-300)}));
}

TEST(LatticeFill, RejectsBadArguments) {
  const std::vector<Shape<2>> box = {Box<2>{.lower = v2(0, 0), .upper = v2(1, 1)}};
  EXPECT_THROW(fillLattice<2>(box, 0.0), std::invalid_argument);
  EXPECT_THROW(fillLattice<2>(box, -0.1), std::invalid_argument);
  EXPECT_THROW(fillLattice<2>(box, NAN), std::invalid_argument);
  EXPECT_THROW(fillLattice<2>(box, 1e-320), std::invalid_argument);  // no grid below it
  EXPECT_THROW(fillLattice<2>(box, 1e300), std::invalid_argument);
  EXPECT_THROW(fillLattice<2>({}, 0.1), std::invalid_argument);
  try {
    fillLattice<2>({box[0], Box<2>{.lower = v2(0, 0), .upper = v2(1, 0)}}, 0.1);
    ADD_FAILURE() << "a degenerate box was filled";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("shape 1 is invalid: box: upper <= lower on axis y"),
              std::string::npos)
        << e.what();
  }
}

TEST(Shape, Names) {
  EXPECT_EQ(shapeName(Shape<3>{Box<3>{}}), "box");
  EXPECT_EQ(shapeName(Shape<3>{Cylinder<3>{}}), "cylinder");
  EXPECT_EQ(shapeName(Shape<3>{Polygon<3>{}}), "polygon");
  EXPECT_EQ(shapeName(Shape<3>{HalfSpace<3>{}}), "half-space");
  EXPECT_EQ(shapeName(Shape<2>{Ball<2>{}}), "ball");
}

// 7. The memory guard counts the lattice points of the union of bounding boxes exactly.

TEST(LatticeFill, MaxPointsGuard) {
  const std::vector<Shape<2>> square = {Box<2>{.lower = v2(0, 0), .upper = v2(1, 1)}};
  const std::string message = lengthErrorOf([&] { fillLattice<2>(square, 0.01, v2(0, 0), 9999); });
  EXPECT_NE(message.find("10000 lattice points"), std::string::npos) << message;
  EXPECT_NE(message.find("limit 9999"), std::string::npos) << message;
  EXPECT_EQ(fillLattice<2>(square, 0.01, v2(0, 0), 10000).size(), 10000u);

  // Overlaps count once, and far-apart shapes do not count the space between them.
  const std::vector<Shape<2>> overlapping = {Box<2>{.lower = v2(0, 0), .upper = v2(0.5, 0.5)},
                                             Box<2>{.lower = v2(0.3, 0.2), .upper = v2(0.8, 0.6)}};
  EXPECT_EQ(fillLattice<2>(overlapping, 0.05, v2(0, 0), 156).size(), 156u);
  EXPECT_THROW(fillLattice<2>(overlapping, 0.05, v2(0, 0), 155), std::length_error);
  const std::vector<Shape<3>> apart = {
      Box<3>{.lower = v3(0, 0, 0), .upper = v3(0.1, 0.1, 0.1)},
      Box<3>{.lower = v3(100, 100, 100), .upper = v3(100.1, 100.1, 100.1)}};
  EXPECT_EQ(fillLattice<3>(apart, 0.01, v3(0, 0, 0), 2000).size(), 2000u);
  EXPECT_THROW(fillLattice<3>(apart, 0.01, v3(0, 0, 0), 1999), std::length_error);

  // A mistyped dx fails at once instead of exhausting memory.
  const std::string huge =
      lengthErrorOf([] { fillLattice<3>({Ball<3>{.centre = v3(0, 0, 0), .radius = 1.0}}, 1e-5); });
  EXPECT_NE(huge.find("limit 50000000"), std::string::npos) << huge;
}

}  // namespace

// LocalityOrder.hpp: the longest axis slowest puts every neighbour within a few cross-sections
// of a particle's index; the lattice fill's order (x fastest) puts it whole x-y layers away.
TEST(LocalityOrder, NeighboursOfABeamAreWithinAFewCrossSections) {
  const double dx = 0.0125, H = 2.1 * dx;
  auto X = cellCentredLattice<3>(Vec3::Zero(), {80, 8, 8}, dx);
  auto widestReach = [&](const std::vector<Vec3>& points) {
    long widest = 0;
    for (std::size_t i = 0; i < points.size(); ++i)
      for (std::size_t j = 0; j < points.size(); ++j)
        if ((points[i] - points[j]).norm() < H)
          widest = std::max(widest, std::labs(long(i) - long(j)));
    return widest;
  };
  EXPECT_GE(widestReach(X), 2 * 80 * 8);  // two x-y layers of 640
  sortForLocality<3>(X);
  EXPECT_LT(widestReach(X), 3 * 8 * 8);  // two cross-sections of 64 and one less than a third
  // x slowest, then z, then y (extents 1, 0.1, 0.1: equal extents keep the fill's z over y)
  EXPECT_EQ((localityAxes<3>(X)), (std::array<int, 3>{0, 2, 1}));
  for (std::size_t i = 1; i < X.size(); ++i)
    ASSERT_TRUE(X[i - 1][0] < X[i][0] || (X[i - 1][0] == X[i][0] && X[i - 1][2] < X[i][2]) ||
                (X[i - 1][0] == X[i][0] && X[i - 1][2] == X[i][2] && X[i - 1][1] < X[i][1]))
        << i;
}

TEST(LocalityOrder, ACubeKeepsTheFillsOrderAndAnyInputOrderGivesTheSame) {
  const double dx = 0.1;
  const auto cube = cellCentredLattice<3>(Vec3::Zero(), {5, 5, 5}, dx);
  auto sorted = cube;
  sortForLocality<3>(sorted);
  EXPECT_EQ(sorted, cube);
  // a plate thin in x and longest in y: y slowest, x fastest
  auto plate = cellCentredLattice<3>(Vec3::Zero(), {3, 12, 7}, dx);
  EXPECT_EQ((localityAxes<3>(plate)), (std::array<int, 3>{1, 2, 0}));
  auto shuffled = plate;
  std::reverse(shuffled.begin(), shuffled.end());
  std::rotate(shuffled.begin(), shuffled.begin() + 40, shuffled.end());
  sortForLocality<3>(plate);
  sortForLocality<3>(shuffled);
  EXPECT_EQ(shuffled, plate);
  for (std::size_t i = 1; i < plate.size(); ++i)
    ASSERT_LE(plate[i - 1][1], plate[i][1]) << i;
  // 2D: a bar along x is numbered with x slowest
  auto bar = cellCentredLattice<2>(Vec<2>::Zero(), {20, 4}, dx);
  sortForLocality<2>(bar);
  EXPECT_EQ((localityAxes<2>(bar)), (std::array<int, 2>{0, 1}));
  for (std::size_t i = 1; i < bar.size(); ++i)
    ASSERT_LE(bar[i - 1][0], bar[i][0]) << i;
  std::vector<Vec<2>> none;
  sortForLocality<2>(none);  // no points: nothing to do
  EXPECT_TRUE(none.empty());
}

TEST(LocalityOrder, LatticeOrderBeforeIsTheFillsOrder) {
  // the lattice fill numbers x fastest and the last axis slowest; latticeOrderBefore orders
  // the fill's points exactly as it made them, whatever order they are handed in
  const auto block = cellCentredLattice<3>(Vec3::Zero(), {4, 3, 5}, 0.1);
  for (std::size_t i = 1; i < block.size(); ++i) {
    ASSERT_TRUE(latticeOrderBefore<3>(block[i - 1], block[i])) << i;
    ASSERT_FALSE(latticeOrderBefore<3>(block[i], block[i - 1])) << i;
  }
  EXPECT_FALSE(latticeOrderBefore<3>(block[7], block[7]));  // strict: a point is not before itself
  auto shuffled = block;
  sortForLocality<3>(shuffled);  // numbered otherwise (z slowest here, then x)
  EXPECT_NE(shuffled, block);
  std::sort(shuffled.begin(), shuffled.end(),
            [](const Vec3& p, const Vec3& q) { return latticeOrderBefore<3>(p, q); });
  EXPECT_EQ(shuffled, block);
}
