// Throughput benchmark on the 3D cantilever of DESIGN.md section 6: particle-steps per second
// of the full step (F, P, internal and hourglass forces, integrator). Not a test: it prints.
#include <omp.h>

#include <boost/program_options.hpp>
#include <chrono>
#include <cmath>
#include <iostream>

#include "tlsph/Lattice.hpp"
#include "tlsph/Solver.hpp"

namespace po = boost::program_options;
using namespace tlsph;

int main(int argc, char** argv) {
  double dx = 0.0125, supportRatio = 2.1, alpha = 10.0;
  long steps = 200;
  std::string material = "neo-hookean", correction = "linear", form = "energy",
              quadrature = "nodal";
  po::options_description options("tlsph_bench: 3D cantilever throughput");
  options.add_options()("help", "this help")("dx", po::value(&dx)->default_value(dx),
                                             "particle spacing [m] (0.0125: 80 x 8 x 8)")(
      "support", po::value(&supportRatio)->default_value(supportRatio),
      "kernel support H/dx (2.1: 32 neighbours)")("alpha", po::value(&alpha)->default_value(alpha),
                                                  "hourglass coefficient")(
      "material", po::value(&material)->default_value(material), "material model")(
      "steps", po::value(&steps)->default_value(steps), "time steps to time")(
      "correction", po::value(&correction)->default_value(correction),
      "gradient correction: linear or quadratic")("form", po::value(&form)->default_value(form),
                                                  "hourglass form: energy or ganzenmueller")(
      "quadrature", po::value(&quadrature)->default_value(quadrature),
      "strain-energy quadrature: nodal or taylor (taylor needs the quadratic correction)");
  po::variables_map vm;
  po::store(po::parse_command_line(argc, argv, options), vm);
  po::notify(vm);
  if (vm.count("help")) {
    std::cout << options;
    return 0;
  }

  Scene<3> scene;
  scene.materials.push_back(
      makeMaterial(material, ElasticConstants::fromYoungPoisson(1.0e7, 0.3), 1000.0));
  scene.supportRadius = supportRatio * dx;
  scene.hourglassCoefficient = alpha;
  scene.hourglassForm = parseHourglassForm(form);
  scene.gradientCorrection = parseGradientCorrection(correction);
  scene.quadrature = parseQuadrature(quadrature);
  scene.gravity = Vec3(0, 0, -1.0);
  const int nx = static_cast<int>(std::lround(1.0 / dx));
  const int ny = static_cast<int>(std::lround(0.1 / dx));
  const int ghostLayers = static_cast<int>(std::ceil(supportRatio));
  const double V = dx * dx * dx;
  for (const auto& X : cellCentredLattice<3>(Vec3(0, -0.05, -0.05), {nx, ny, ny}, dx))
    scene.particles.add(X, V, 1000.0 * V, 0);
  for (const auto& X :
       cellCentredLattice<3>(Vec3(-ghostLayers * dx, -0.05, -0.05), {ghostLayers, ny, ny}, dx))
    scene.particles.add(X, V, 1000.0 * V, 0, Motion::Prescribed);

  Solver<3> solver(scene);
  const auto& nb = solver.reference().neighbours;
  std::cout << "particles " << scene.particles.size() << " (" << nx * ny * ny << " body), "
            << "mean neighbours " << double(nb.pairCount()) / nb.particleCount() << ", threads "
            << omp_get_max_threads() << ", dt " << solver.timeStep() << ", " << correction
            << " correction, " << quadrature << " quadrature, hourglass " << form << "\n";
  solver.step();  // warm-up
  const auto start = std::chrono::steady_clock::now();
  for (long s = 0; s < steps; ++s)
    solver.step();
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const double rate = double(scene.particles.size()) * steps / seconds;
  std::cout << "steps " << steps << ", wall " << seconds << " s, particle-steps/s " << rate
            << ", tip u_z " << scene.particles.displacement[nx - 1].z() << "\n";
  return 0;
}
