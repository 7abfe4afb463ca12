// The halo exchange on 1-4 ranks (ctest runs it under mpirun --oversubscribe): on 2D and 3D
// lattices partitioned among the ranks, every rank fills its own particles' values, and after
// one exchange its halo holds exactly the owners' values, every other entry untouched; scalars
// and D-vectors alike. Exit status 0 when every rank agrees.
#include <mpi.h>

#include <cmath>
#include <cstdio>
#include <limits>

#include "distributed/HaloExchange.hpp"
#include "geometry/Lattice.hpp"

using namespace tlsph;

namespace {

double valueOf(Index i) {
  return 1.0 + 0.5 * i;
}

template <int D>
int check(const std::array<int, D>& counts, const char* name) {
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  const double dx = 0.01;
  const auto X = cellCentredLattice<D>(Vec<D>::Zero(), counts, dx);
  const NeighbourList nb = buildNeighbourList<D>(X, 2.1 * dx);
  const DomainPartition partition = partitionParticles<D>(X, nb, size);
  HaloExchange halo(MPI_COMM_WORLD, partition, nb);
  const Index n = static_cast<Index>(X.size());
  const double unset = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> scalar(n, unset);
  std::vector<Vec<D>> vector(n, Vec<D>::Constant(unset));
  for (Index i : partition.owned[rank]) {
    scalar[i] = valueOf(i);
    vector[i] = X[i];
  }
  halo.exchange(scalar);
  halo.exchange(vector);
  std::vector<char> inHalo(n, 0);
  for (Index j : partition.halo[rank])
    inHalo[j] = 1;
  int errors = 0;
  for (Index i = 0; i < n; ++i) {
    const bool known = partition.part[i] == rank || inHalo[i];
    if (known) {
      errors += scalar[i] != valueOf(i);
      errors += vector[i] != X[i];
    } else {
      errors += !std::isnan(scalar[i]);
      errors += !std::isnan(vector[i][0]);
    }
  }
  if (halo.haloCount() != partition.halo[rank].size()) ++errors;
  int total = 0;
  MPI_Allreduce(&errors, &total, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  long received = static_cast<long>(halo.haloCount()), all = 0;
  MPI_Reduce(&received, &all, 1, MPI_LONG, MPI_SUM, 0, MPI_COMM_WORLD);
  if (rank == 0)
    std::printf("%s: %d particles on %d ranks (%s), %ld halo particles in all: %s\n", name,
                static_cast<int>(n), size, partition.method.c_str(), all,
                total == 0 ? "ok" : "FAILED");
  return total;
}

}  // namespace

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  int failures = 0;
  failures += check<3>({24, 10, 6}, "3D block") != 0;
  failures += check<2>({40, 25}, "2D plate") != 0;
  MPI_Finalize();
  return failures == 0 ? 0 : 1;
}
