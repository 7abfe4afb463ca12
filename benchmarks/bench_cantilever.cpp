// Throughput benchmark on the 3D cantilever of DESIGN.md section 6: particle-steps per second
// of the full step (F, P, internal and hourglass forces, integrator). Not a test: it prints.
// Under mpirun (a build with MPI) the step is distributed as in `tlsph run`, and the time in
// halo exchanges and reductions is reported (issue 11's scaling tables, docs/performance.md).
#include <omp.h>

#include <boost/program_options.hpp>
#include <chrono>
#include <cmath>
#include <iostream>
#include <memory>

#include "tlsph/Lattice.hpp"
#include "tlsph/Solver.hpp"
#ifdef TLSPH_HAVE_MPI
#include <mpi.h>

#include "parallel/MpiCommunicator.hpp"
#endif

namespace po = boost::program_options;
using namespace tlsph;

int main(int argc, char** argv) {
#ifdef TLSPH_HAVE_MPI
  const bool mpi = launchedByMpi();
  if (mpi) MPI_Init(&argc, &argv);
  std::unique_ptr<MpiCommunicator> comm;
  int ranks = 1;
  if (mpi) MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  if (ranks > 1) comm = std::make_unique<MpiCommunicator>(MPI_COMM_WORLD);
  const bool root = !comm || comm->rank() == 0;
  if (!root) std::cout.setstate(std::ios::failbit);
#else
  const int ranks = 1;
#endif
  double dx = 0.0125, supportRatio = 2.1, alpha = 10.0, length = 1.0;
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
      "length", po::value(&length)->default_value(length),
      "beam length [m] (cross-section 0.1 x 0.1; weak scaling: length x ranks)")(
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
#ifdef TLSPH_HAVE_MPI
    if (mpi) MPI_Finalize();
#endif
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
  const int nx = static_cast<int>(std::lround(length / dx));
  const int ny = static_cast<int>(std::lround(0.1 / dx));
  const int ghostLayers = static_cast<int>(std::ceil(supportRatio));
  const double V = dx * dx * dx;
  for (const auto& X : cellCentredLattice<3>(Vec3(0, -0.05, -0.05), {nx, ny, ny}, dx))
    scene.particles.add(X, V, 1000.0 * V, 0);
  for (const auto& X :
       cellCentredLattice<3>(Vec3(-ghostLayers * dx, -0.05, -0.05), {ghostLayers, ny, ny}, dx))
    scene.particles.add(X, V, 1000.0 * V, 0, Motion::Prescribed);

#ifdef TLSPH_HAVE_MPI
  Solver<3> solver(scene, {}, comm.get());
#else
  Solver<3> solver(scene);
#endif
  const auto& nb = solver.reference().neighbours;
  std::cout << "particles " << scene.particles.size() << " (" << nx * ny * ny << " body), "
            << "mean neighbours " << double(nb.pairCount()) / nb.particleCount() << ", threads "
            << omp_get_max_threads() << ", dt " << solver.timeStep() << ", " << correction
            << " correction, " << quadrature << " quadrature, hourglass " << form << "\n";
  if (ranks > 1)
    std::cout << "ranks " << ranks << ", partition " << solver.partition().method << ", halo "
              << solver.partition().halo << " particles in all, imbalance "
              << solver.partition().imbalance << "\n";
  solver.step();  // warm-up
#ifdef TLSPH_HAVE_MPI
  if (comm) comm->barrier();
  const MpiCommunicator::Traffic halo0 = comm ? comm->haloTraffic() : MpiCommunicator::Traffic{},
                                 reduce0 =
                                     comm ? comm->reductionTraffic() : MpiCommunicator::Traffic{};
#endif
  const auto start = std::chrono::steady_clock::now();
  for (long s = 0; s < steps; ++s)
    solver.step();
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const double rate = double(scene.particles.size()) * steps / seconds;
  solver.synchronize();  // (distributed: the tip's displacement from its rank)
  std::cout << "steps " << steps << ", wall " << seconds << " s, particle-steps/s " << rate
            << ", tip u_z " << scene.particles.displacement[nx - 1].z() << "\n";
#ifdef TLSPH_HAVE_MPI
  if (comm) {
    // Per step, the slowest rank's time in exchanges (their wait for the slowest included)
    // and reductions, and the halo bytes received per step by all ranks together.
    double t[2] = {(comm->haloTraffic().seconds - halo0.seconds) / steps,
                   (comm->reductionTraffic().seconds - reduce0.seconds) / steps};
    double bytes = (comm->haloTraffic().bytes - halo0.bytes) / steps;
    MPI_Allreduce(MPI_IN_PLACE, t, 2, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
    MPI_Allreduce(MPI_IN_PLACE, &bytes, 1, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
    // What an observation costs: the whole state gathered onto every rank (once per series
    // row, frame or check). The second gather is timed (the first also touches its buffers'
    // pages for the first time), after a barrier (not the wait for the last rank's step).
    double gatherSeconds = 0.0;
    for (int k = 0; k < 2; ++k) {
      if (k == 1) solver.step();
      comm->barrier();
      const auto gatherStart = std::chrono::steady_clock::now();
      solver.synchronize();
      gatherSeconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - gatherStart).count();
    }
    std::cout << "per step: wall " << seconds / steps * 1e3 << " ms, halo exchanges " << t[0] * 1e3
              << " ms (" << bytes / 1e6 << " MB received by all ranks), reductions " << t[1] * 1e3
              << " ms; gathering the state for an observation " << gatherSeconds * 1e3 << " ms\n";
  }
  comm.reset();
  if (mpi) MPI_Finalize();
#endif
  return 0;
}
