// Throughput benchmark on the 3D cantilever of docs/method.md section 6: particle-steps per second
// of the full step (F, P, internal and hourglass forces, integrator). Not a test: it prints.
// With it, the roofline's numbers (docs/performance.md): the force passes' counted
// memory traffic per particle-step, the bandwidth that traffic reaches, and the machine's own
// bandwidth (a plain copy on the same threads).
// Under mpirun (a build with MPI) the step is distributed as in `tlsph run`, and the time in
// halo exchanges and reductions is reported (the scaling tables of docs/performance.md).
#include <algorithm>
#include <boost/program_options.hpp>
#include <chrono>
#include <cmath>
#include <iostream>
#include <memory>
#include <random>
#include <vector>

#include "app/SpectralLimit.hpp"
#include "execution/LargePageAllocator.hpp"
#include "execution/Prefetch.hpp"
#include "execution/Threads.hpp"
#include "explicit/Solver.hpp"
#include "geometry/Lattice.hpp"
#include "geometry/LocalityOrder.hpp"
#include "scene/ParticleSetChecks.hpp"
#ifdef TLSPH_HAVE_MPI
#include <mpi.h>

#include "distributed/MpiCommunicator.hpp"
#endif

namespace po = boost::program_options;
using namespace tlsph;

namespace {

// Bytes per second of `b = a` over 2 x 512 MB (read + written, as STREAM counts a copy), best
// of five, on the OpenMP threads; far out of any cache.
double copyBandwidth() {
  const std::size_t n = std::size_t(1) << 26;
  std::vector<double> a(n), b(n);
#pragma omp parallel for schedule(static)
  for (std::size_t i = 0; i < n; ++i) {  // first touch by the threads that copy
    a[i] = double(i);
    b[i] = 0.0;
  }
  double best = 0.0;
  for (int r = 0; r < 5; ++r) {
    const auto start = std::chrono::steady_clock::now();
#pragma omp parallel for schedule(static)
    for (std::size_t i = 0; i < n; ++i)
      b[i] = a[i];
    const double t =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    best = std::max(best, 2.0 * sizeof(double) * n / t);
  }
  if (b[n / 2] != a[n / 2]) std::cerr << "copy check failed\n";
  return best;
}

}  // namespace

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
  double dx = 0.0125, supportRatio = 2.1, alpha = 10.0, length = 1.0, jitter = 0.0,
         cfl = kDefaultCfl;
  long steps = 200, particles = 0;
  bool stream = true;
  std::string material = "neo-hookean", correction = "linear", form = "energy",
              quadrature = "nodal";
  po::options_description options("tlsph_bench: 3D cantilever throughput");
  options.add_options()("help", "this help")("dx", po::value(&dx)->default_value(dx),
                                             "particle spacing [m] (0.0125: 80 x 8 x 8)")(
      "support", po::value(&supportRatio),
      "kernel support H/dx; default 2.1 on the lattice (32 neighbours), 2.5 with --jitter above "
      "1e-4, as a scene's particle file off a lattice gets")(
      "alpha", po::value(&alpha)->default_value(alpha), "hourglass coefficient")(
      "material", po::value(&material)->default_value(material), "material model")(
      "steps", po::value(&steps)->default_value(steps), "time steps to time")(
      "particles", po::value(&particles),
      "about this many body particles: sets dx (the 1 m beam, n x n cross-section, 10 n^3)")(
      "no-stream", "skip measuring the copy bandwidth")(
      "length", po::value(&length)->default_value(length),
      "beam length [m] (cross-section 0.1 x 0.1; weak scaling: length x ranks)")(
      "jitter", po::value(&jitter)->default_value(jitter),
      "move each particle off the lattice by up to this fraction of dx per axis, below 0.25 "
      "(1e-6: the lattice's physics with no two neighbourhoods alike to the bit, so no "
      "per-pair row is shared)")("correction", po::value(&correction)->default_value(correction),
                                 "gradient correction: linear or quadratic")(
      "form", po::value(&form)->default_value(form), "hourglass form: energy or ganzenmueller")(
      "quadrature", po::value(&quadrature)->default_value(quadrature),
      "strain-energy quadrature: nodal or taylor (taylor needs the quadratic correction)")(
      "cfl", po::value(&cfl)->default_value(cfl),
      "C_cfl of the wave-speed time step (a scene's [time] cfl)");
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

  if (particles > 0) dx = 0.1 / std::max(1L, std::lround(std::cbrt(particles / (10.0 * length))));
  stream = !vm.count("no-stream");
  if (!vm.count("support"))
    supportRatio = jitter > kLatticeTolerance ? kOffLatticeSupportRatio : 2.1;
  if (!(jitter >= 0.0 && jitter < 0.25)) {
    std::cerr << "tlsph_bench: --jitter " << jitter
              << ": expected a fraction of dx in [0, 0.25) (larger moves a particle across the "
                 "clamp's plane or onto a neighbour)\n";
    return 2;
  }
  if (!(cfl > 0.0)) {
    std::cerr << "tlsph_bench: --cfl " << cfl << ": expected a positive C_cfl\n";
    return 2;
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
  // One lattice for the beam (x > 0) and its clamped ghost layers (x < 0), so that the offsets
  // between them are exact too: the body first, then the ghosts; numbered as a scene's
  // bodies are (the long axis slowest, LocalityOrder.hpp).
  auto lattice =
      cellCentredLattice<3>(Vec3(-ghostLayers * dx, -0.05, -0.05), {ghostLayers + nx, ny, ny}, dx);
  sortForLocality<3>(lattice);
  if (jitter > 0.0) {  // a fixed seed: every run places the particles alike
    std::mt19937_64 random(12);
    std::uniform_real_distribution<double> offset(-jitter * dx, jitter * dx);
    for (auto& X : lattice)
      for (int d = 0; d < 3; ++d)
        X[d] += offset(random);
  }
  Index tip = 0;  // the body's particle at the largest x, lowest y and z
  for (const auto& X : lattice)
    if (X.x() > 0.0) {
      const Index i = scene.particles.add(X, V, 1000.0 * V, 0);
      const Vec3& T = scene.particles.referencePosition[tip];
      if (X.x() > T.x() || (X.x() == T.x() && (X.z() < T.z() || (X.z() == T.z() && X.y() < T.y()))))
        tip = i;
    }
  for (const auto& X : lattice)
    if (X.x() < 0.0) scene.particles.add(X, V, 1000.0 * V, 0, Motion::Prescribed);

#ifdef TLSPH_HAVE_MPI
  Solver<3> solver(scene, {cfl}, comm.get());
#else
  Solver<3> solver(scene, {cfl});
#endif
  // The scene's default step: the rule, capped by the operator's fastest mode (off the
  // lattice the cap binds).
  solver.limitTimeStep(estimateSpectralStep(scene, solver));
  const auto& nb = solver.reference().neighbours;
  std::cout << "particles " << scene.particles.size() << " (" << nx * ny * ny << " body), "
            << "mean neighbours " << double(nb.pairCount()) / nb.particleCount() << ", threads "
            << maxThreads() << ", dt " << solver.timeStep() << ", " << correction << " correction, "
            << quadrature << " quadrature, hourglass " << form;
  if (jitter > 0.0) std::cout << ", jitter " << jitter << " dx";
  std::cout << "\n";
  if (const SpectralStep& cap = solver.spectralStep(); cap.made)
    std::cout << "step: rule " << solver.stableStepRule().dt << " s, cap 0.8 x 2 / omega_max "
              << cap.limit << " s (" << cap.products << " products, " << cap.seconds << " s)"
              << (cap.binds ? ": the cap sets the step" : "") << "\n";
  if (ranks > 1)
    std::cout << "ranks " << ranks << ", partition " << solver.partition().method << ", halo "
              << solver.partition().halo << " particles in all, imbalance "
              << solver.partition().imbalance << "\n";
  solver.step();  // warm-up
  {
    // Whether the kernel gave the per-pair arrays huge pages (LargePageAllocator.hpp): on the
    // Intel machine the rate depended on it by 0-17 % (docs/performance.md).
    const auto& g = solver.reference().correctedGradient;
    const auto map = largepages::mappingOf(g.data());
    std::cout << "pair arrays: " << (map.advised ? "advised for huge pages" : "not advised")
              << ", the gradient vectors' mapping " << map.hugePageBytes / 1048576 << " of "
              << map.bytes / 1048576 << " MiB on huge pages\n";
    // Whether the pair loops prefetch their gathers (Prefetch.hpp: out of the last-level cache).
    std::cout << "gathers prefetched: " << (solver.forces().prefetchGathers() ? "yes" : "no")
              << " (last-level cache " << lastLevelCacheBytes() / 1048576 << " MiB)\n";
  }
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
            << ", tip u_z " << scene.particles.displacement[tip].z() << "\n";
  if (!std::isfinite(scene.particles.displacement[tip].z())) {
    std::cerr << "tlsph_bench: the run blew up (tip displacement not finite); its rate is not "
                 "a measurement\n";
    return 1;
  }
  {
    // The energy books: what the undamped run gained or lost against the work of gravity,
    // relative to its kinetic + strain + hourglass energy (a run's guard stops at 5 %).
    const EnergyBalance e = solver.energyBalance();
    const double scale = e.kinetic + e.strain + e.hourglass;
    const double error = scale > 0.0 ? std::abs(e.total()) / scale : 0.0;
    std::cout << "energy books: balance " << e.total() << " J of " << scale << " J (" << error
              << " relative)\n";
    if (!(error < 0.05)) {
      std::cerr << "tlsph_bench: the energy books are off by " << error
                << " of the energy: the run is unstable; its rate is not a measurement\n";
      return 1;
    }
  }
  // The roofline: what the force passes must move per particle-step (TlsphForces::traffic),
  // against what a plain copy moves on this machine with the same threads.
  const auto traffic = solver.forces().traffic();
  const double pairsPerParticle = double(nb.pairCount()) / nb.particleCount();
  const double bytes = traffic.perPair * pairsPerParticle + traffic.perParticle;
  std::cout << "traffic (counted, force passes) " << traffic.perPair << " B per pair ("
            << traffic.unsharedPerPair << " with every particle's rows stored) + "
            << traffic.perParticle << " B per particle = " << bytes / 1e3
            << " kB per particle-step; reached " << rate * bytes / 1e9 << " GB/s";
  if (stream && ranks == 1) {
    const double copy = copyBandwidth();
    std::cout << " = " << 100.0 * rate * bytes / copy << " % of a plain copy's " << copy / 1e9
              << " GB/s (" << maxThreads() << " threads)";
  }
  std::cout << "\n";
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
