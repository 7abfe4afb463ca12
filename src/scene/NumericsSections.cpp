// How the scene is solved: [kernel], [hourglass], [artificial_viscosity], [damping], [static]
// and [time].
#include <algorithm>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>

#include "method/IntegrationConstraint.hpp"
#include "method/Kernel.hpp"
#include "method/TimeStep.hpp"
#include "model/RigidModes.hpp"
#include "scene/Builder.hpp"
#include "scene/ParticleSetChecks.hpp"

namespace tlsph::scene_build {

// The largest rigid part of the loads of a body nothing holds, per unit of their size.
constexpr double kFreeBodyBalance = 1e-3;

template <int D>
void Builder<D>::readDiscretisation() {
  SectionReader k(config_, "kernel");
  try {
    setup_.scene.kernel =
        parseKernelType(k.word("type", "wendland-c2", {"wendland-c2", "cubic-bspline"}));
  } catch (const std::invalid_argument& e) {
    throw k.error("type", e.what());
  }
  // A mesh body's nodes are not a lattice: its quadratic fit needs the wider support across
  // faces (as a particle file's does, ParticleSetChecks.hpp), and its gradient vectors the
  // integration constraint, without which the error levels off under refinement. The linear
  // one in 2D, where its solve costs about what the rest of the run does and buys the most
  // accuracy per second; the uniform one in 3D, where its solve alone would cost several runs.
  const bool mesh = meshBodyGiven();
  const char* meshConstraint = D == 2 ? "linear" : "uniform";
  const double ratio = k.positive("support", mesh ? kOffLatticeSupportRatio : 2.1);
  if (ratio < 1.5 || ratio > 5.0)
    throw k.error("support", "H/dx = " + fmt(ratio) + " is outside the useful range [1.5, 5]");
  supportRatio_ = ratio;
  setup_.scene.gradientCorrection =
      parseGradientCorrection(k.word("correction", "quadratic", {"linear", "quadratic"}));
  setup_.scene.supportRadius = ratio * setup_.dx;
  // nodal = the one-point sum_I V_I psi(F_I); taylor adds its second-order term
  // (TaylorQuadrature.hpp), the default where it can run: it needs the quadratic fit.
  const bool quadratic = setup_.scene.gradientCorrection == GradientCorrection::Quadratic;
  setup_.scene.quadrature =
      parseQuadrature(k.word("quadrature", quadratic ? "taylor" : "nodal", {"nodal", "taylor"}));
  if (setup_.scene.quadrature == Quadrature::Taylor && !quadratic)
    throw k.error("quadrature",
                  "taylor needs correction = quadratic (its second derivatives come from the "
                  "quadratic fit)");
  if (setup_.scene.quadrature == Quadrature::Taylor) warnNearlyIncompressible();
  // The gradient vectors corrected so that a uniform stress balances its tractions at every
  // particle, and with `linear` a linearly varying one too in the filtered sense
  // (method/IntegrationConstraint.hpp): needs the boundary of a mesh body.
  const std::string constraint =
      k.word("integration_constraint", mesh ? meshConstraint : "false",
             {"false", "true", "uniform", "linear", "no", "yes", "off", "on", "0", "1"});
  integrationLinear_ = constraint == "linear";
  integrationConstraint_ =
      integrationLinear_ || constraint == "uniform" || k.flag("integration_constraint", mesh);
  // (Without any constraint the filter is ignored: the multigrid's coarse levels turn the
  // constraint off and keep the rest of the scene.)
  if (k.has("integration_filter") && integrationConstraint_ && !integrationLinear_)
    throw k.error("integration_filter", "applies only with integration_constraint = linear");
  setup_.scene.integrationFilter =
      integrationLinear_ ? k.positive("integration_filter", kLinearConstraintFilter) : 0.0;
  if (mesh && !k.has("support"))
    setup_.conditions.push_back("kernel: support " + fmt(ratio) +
                                " dx (a mesh body: its nodes are not a lattice, and the quadratic "
                                "fit needs a second layer of neighbours across each face)");
  if (mesh && !k.has("integration_constraint"))
    setup_.conditions.push_back(std::string("kernel: integration_constraint = ") + meshConstraint +
                                " (a mesh body: a uniform" +
                                (D == 2 ? " and a linearly varying" : "") +
                                " stress balances its tractions at every particle)");
  k.finish();
  SectionReader h(config_, "hourglass");
  setup_.scene.hourglassCoefficient = h.nonNegative("alpha", 10.0);
  setup_.scene.hourglassForm =
      parseHourglassForm(h.word("form", "energy", {"energy", "ganzenmueller"}));
  setup_.scene.hourglassGradient =
      parseHourglassGradient(h.word("gradient", "corrected", {"corrected", "linear"}));
  h.finish();
  SectionReader v(config_, "artificial_viscosity");
  setup_.scene.viscosity.linear = v.nonNegative("linear", 0.0);
  setup_.scene.viscosity.quadratic = v.nonNegative("quadratic", 0.0);
  v.finish();
}

template <int D>
void Builder<D>::readTimeAndDamping() {
  SectionReader d(config_, "damping");
  setup_.scene.damping.viscous = d.nonNegative("viscous", 0.0);
  setup_.scene.damping.kinetic = d.flag("kinetic", false);
  d.finish();
  SectionReader s(config_, "static");
  setup_.run.quasiStatic = s.flag("enabled", config_.hasSection("static"));
  setup_.run.tolerance = s.positive("tolerance", 1e-5);
  setup_.run.checkEvery = std::max(1L, s.integer("check_every", 50));
  const bool newton = s.word("solver", "damped", {"damped", "newton"}) == "newton";
  setup_.run.staticSolver =
      newton ? RunSettings::StaticSolver::Newton : RunSettings::StaticSolver::Damped;
  auto& n = setup_.run.newton;
  n.tolerance = setup_.run.tolerance;
  const long loadSteps = s.integer("load_steps", 1);
  if (loadSteps < 1 || loadSteps > 100000)
    throw s.error("load_steps",
                  "must be between 1 and 100000, got " + config_.get("static", "load_steps"));
  n.loadSteps = static_cast<int>(loadSteps);
  const long iterations = s.integer("max_iterations", 30);
  if (iterations < 1 || iterations > 100000)
    throw s.error("max_iterations",
                  "must be between 1 and 100000, got " + config_.get("static", "max_iterations"));
  n.maxIterations = static_cast<int>(iterations);
  const std::string preconditioner =
      s.word("preconditioner", "auto", {"auto", "cholesky", "multigrid"});
  n.preconditioner = preconditioner == "cholesky"    ? NewtonPreconditioner::Cholesky
                     : preconditioner == "multigrid" ? NewtonPreconditioner::Multigrid
                                                     : NewtonPreconditioner::Auto;
  s.finish();
  SectionReader t(config_, "time");
  setup_.solver.cfl = t.positive("cfl", kDefaultCfl);
  setup_.solver.timeStep = t.nonNegative("dt", 0.0);
  setup_.solver.spectralLimit = t.flag("spectral_limit", true);
  // A Newton static run has no time to march; `end` only scales the default output interval.
  setup_.run.endTime =
      newton && setup_.run.quasiStatic ? t.positive("end", 1.0) : t.positive("end");
  setup_.run.maxSteps = t.integer("max_steps", 0);
  t.finish();
  if (setup_.run.quasiStatic && newton && setup_.scene.hourglassCoefficient != 0.0 &&
      setup_.scene.hourglassForm != HourglassForm::Energy)
    throw InputError(config_.where("static", "solver"), "static", "solver",
                     "solver = newton needs the hourglass penalty's energy form ([hourglass] "
                     "form = energy): the textbook force (6.80)-(6.81) is not the gradient of "
                     "an energy and has no symmetric tangent");
  if (setup_.run.quasiStatic) {
    if (!newton && !setup_.scene.damping.any())
      throw InputError(config_.where("static", "enabled"), "static", "enabled",
                       "a static run needs damping: set [damping] kinetic = true or viscous > 0, "
                       "or solve it with [static] solver = newton");
    if (setup_.scene.prescriptions.empty() && setup_.scene.mirrorGhosts.empty())
      checkFreeBodyLoads(newton);
  }
}

// A static run of bodies nothing holds is determined up to a rigid motion, and has a solution
// only when the loads balance: no gravity, and the loads that ramp together (the same ramp
// time) with no rigid part, |Q^T f| / |f| with Q the rigid motions (model/RigidModes.hpp).
// A pressure on a closed curved surface leaves a rigid part of the surface's discretisation
// error (its area vectors follow the true surface); the Newton solver leaves that out, so a
// limit far above it and far below any real imbalance tells the two apart.
template <int D>
void Builder<D>::checkFreeBodyLoads(bool newton) {
  const auto& p = setup_.scene.particles;
  const std::string hold =
      "add a [clamp.NAME] or a [prescribe.NAME] section, or it drifts away under its loads";
  if (!newton)
    throw InputError(config_.where("static", "enabled"), "static", "enabled",
                     "a static run needs the body held: nothing holds it; " + hold +
                         " (solver = newton solves a body nothing holds if its loads balance)");
  if (!setup_.scene.gravity.isZero())
    throw InputError(config_.where("static", "enabled"), "static", "enabled",
                     "a static run needs the body held: nothing holds it, and gravity has no "
                     "load to balance it; " +
                         hold);
  if (setup_.scene.loads.empty())
    throw InputError(config_.where("static", "enabled"), "static", "enabled",
                     "a static run needs the body held: nothing holds it and no load acts "
                     "on it; " +
                         hold);
  std::vector<Index> all(p.size());
  for (Index i = 0; i < p.size(); ++i)
    all[i] = i;
  RigidModes<D> rigid;
  rigid.update(all, p.referencePosition, std::vector<Vec<D>>(p.size(), Vec<D>::Zero()));
  struct Group {
    Eigen::VectorXd force;
    std::string names;
  };
  std::map<double, Group> byRamp;
  const std::vector<Vec<D>> still(p.size(), Vec<D>::Zero());
  for (const auto& load : setup_.scene.loads) {
    std::vector<Vec<D>> f(p.size(), Vec<D>::Zero());
    if (load.following) {
      load.following->addForce(p.referencePosition, still, 1.0, f);
    } else {
      for (std::size_t k = 0; k < load.particles.size(); ++k)
        f[load.particles[k]] += load.force[k];
    }
    Group& g = byRamp[load.ramp.duration];
    if (g.force.size() == 0) g.force = Eigen::VectorXd::Zero(D * p.size());
    g.names += (g.names.empty() ? "" : ", ") + load.name;
    for (Index i = 0; i < p.size(); ++i)
      g.force.template segment<D>(D * i) += f[i];
  }
  double worst = 0.0;
  for (const auto& [ramp, g] : byRamp) {
    const double imbalance = rigid.rigidPart(g.force) / g.force.norm();
    worst = std::max(worst, imbalance);
    if (imbalance <= kFreeBodyBalance) continue;
    Vec<D> net = Vec<D>::Zero();
    for (Index i = 0; i < p.size(); ++i)
      net += g.force.template segment<D>(D * i);
    std::ostringstream msg;
    msg << "a static run needs the body held: nothing holds it, and its loads do not balance ("
        << g.names << (byRamp.size() > 1 ? ", the loads with this ramp time" : "")
        << "): their resultant force is " << fmt<D>(net) << " N, and their rigid part " << imbalance
        << " of their size (at most " << kFreeBodyBalance << " for a body nothing "
        << "holds); " << hold;
    const std::string first = g.names.substr(0, g.names.find(','));
    throw InputError(config_.where(first, "type"), first, "type", msg.str());
  }
  std::ostringstream line;
  line << "free body: nothing holds the bodies; their loads balance to " << worst
       << " of their size (that rigid part is left out): the static solution is found up to a "
          "rigid motion and reported with none (zero mean translation and rotation)";
  setup_.conditions.push_back(line.str());
}

template void Builder<2>::readDiscretisation();
template void Builder<2>::readTimeAndDamping();
template void Builder<2>::checkFreeBodyLoads(bool);
template void Builder<3>::readDiscretisation();
template void Builder<3>::readTimeAndDamping();
template void Builder<3>::checkFreeBodyLoads(bool);

}  // namespace tlsph::scene_build
