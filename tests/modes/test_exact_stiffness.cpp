// The exact sparse tangent (ExactStiffness): assembled or probed, it is K, i.e. it reproduces
// TangentStiffness::apply() to 1e-10 relative for random vectors, for every numerics (both
// corrections, both quadratures, penalty on and off), free, clamped (mirrored ghosts) and held
// (prescribed particles) bodies in 2D and 3D; and the limit on its size is kept.
#include <gtest/gtest.h>

#include "ModesTestScenes.hpp"
#include "modes/ExactStiffness.hpp"

using namespace tlsph;
using namespace tlsph::testing;

namespace {

template <int D>
void expectExact(const Numerics& n, Shape shape, const std::string& hold) {
  SceneSetup<D> setup = setupOf<D>(bodyText<D>(shape, n, hold));
  TangentAt<D> t(setup.scene);
  const ExactStiffness e =
      exactStiffness(t.K, t.solver.reference(), t.dofs, n.alpha > 0.0, 100'000'000);
  const std::string what = std::to_string(D) + "D " + shapeName(shape) + " " + n.correction + " " +
                           n.quadrature + " alpha " + std::to_string(n.alpha) + " " + hold;
  ASSERT_TRUE(e.made) << what << ": " << e.reason;
  EXPECT_EQ(e.method, t.K.assemblyExact() ? "assembled" : "probed") << what;
  // the test's own random vectors, not the ones exactStiffness checked itself with
  const double mismatch = productMismatch(t.K, e.lower, 4);
  EXPECT_LT(mismatch, 1e-10) << what;
  EXPECT_EQ(e.lower.rows(), t.K.size());
  if (e.method == "probed") {
    // the colouring saves products on all but the smallest bodies
    EXPECT_LE(e.products, t.K.size()) << what;
  }
}

const Numerics kNumerics[] = {{"linear", "nodal", 0.0},     {"linear", "nodal", 10.0},
                              {"quadratic", "nodal", 0.0},  {"quadratic", "nodal", 10.0},
                              {"quadratic", "taylor", 0.0}, {"quadratic", "taylor", 10.0}};

TEST(ExactStiffness, ReproducesApplyIn2D) {
  for (const auto& n : kNumerics)
    for (Shape s : {Shape::Box, Shape::Cylinder, Shape::Polygon})
      expectExact<2>(n, s, "");
  for (const auto& n : kNumerics) {
    expectExact<2>(n, Shape::Box, "clamp");
    expectExact<2>(n, Shape::Box, "prescribe");
  }
}

TEST(ExactStiffness, ReproducesApplyIn3D) {
  for (const auto& n : kNumerics)
    for (Shape s : {Shape::Box, Shape::Cylinder, Shape::Polygon})
      expectExact<3>(n, s, "");
  for (const auto& n : kNumerics) {
    expectExact<3>(n, Shape::Box, "clamp");
    expectExact<3>(n, Shape::Box, "prescribe");
  }
}

TEST(ExactStiffness, ProbingSavesProductsOnALongBody) {
  // a 3D bar 24 x 4 x 4 with the penalty (the widest stencil, three neighbour hops): far fewer
  // products than unknowns, and still K
  std::string text = bodyText<3>(Shape::Box, {"quadratic", "taylor", 10.0});
  text.replace(text.find("upper = 0.05"), 12, "upper = 0.24");
  SceneSetup<3> setup = setupOf<3>(text);
  TangentAt<3> t(setup.scene);
  const ExactStiffness e = exactStiffness(t.K, t.solver.reference(), t.dofs, true, 100'000'000);
  ASSERT_TRUE(e.made) << e.reason;
  std::cout << "24 x 4 x 4 bar: " << t.K.size() << " unknowns, " << e.products << " products ("
            << e.groups << " groups), " << e.nonZeros << " entries\n";
  EXPECT_LT(e.products, t.K.size() / 2);
  EXPECT_LT(productMismatch(t.K, e.lower, 2), 1e-10);
}

TEST(ExactStiffness, KeepsItsLimit) {
  SceneSetup<3> setup = setupOf<3>(bodyText<3>(Shape::Box, {"quadratic", "taylor", 10.0}));
  TangentAt<3> t(setup.scene);
  const ExactStiffness e = exactStiffness(t.K, t.solver.reference(), t.dofs, true, 1000);
  EXPECT_FALSE(e.made);
  EXPECT_NE(e.reason.find("above the limit of 1000"), std::string::npos) << e.reason;
  EXPECT_EQ(e.products, 0);
}

}  // namespace
