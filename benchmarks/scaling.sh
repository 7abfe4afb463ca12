#!/bin/bash
# Strong and weak scaling of the distributed explicit step on this machine (the
# tables in docs/performance.md). Runs build/tlsph_bench (built with MPI) on the 3D cantilever
# at the scene defaults (quadratic correction, Taylor quadrature, energy penalty alpha = 10),
# one OpenMP thread per rank, ranks 1, 2 and 4 (4 oversubscribed on 2 cores), and one rank on
# two threads for comparison. Prints one line per run: particles, ranks x threads, wall per
# step, particle-steps/s, halo exchange and reduction time per step, halo bytes per step, and
# the time to gather the whole state for an observation (series row, frame, check).
# Usage: benchmarks/scaling.sh [strong|weak|all]   (about 15 minutes for all on 2 cores)
set -u
cd "$(dirname "$0")/.."
BENCH=build/tlsph_bench
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
export OMPI_MCA_btl_vader_single_copy_mechanism=none
what=${1:-all}
run() {  # ranks threads steps dx length
  local ranks=$1 threads=$2 steps=$3 dx=$4 length=$5 out
  local args="--steps $steps --dx $dx --length $length --correction quadratic --quadrature taylor"
  if [ "$ranks" = 1 ]; then
    out=$(OMP_NUM_THREADS=$threads $BENCH $args 2>&1)
  else
    out=$(OMP_NUM_THREADS=$threads mpirun -np "$ranks" --oversubscribe $BENCH $args 2>&1)
  fi
  local n rate wall halo red bytes
  n=$(grep -o "^particles [0-9]*" <<<"$out" | cut -d' ' -f2)
  rate=$(grep -o "particle-steps/s [0-9.e+-]*" <<<"$out" | cut -d' ' -f2)
  wall=$(grep -o "wall [0-9.e+-]* s" <<<"$out" | head -1 | cut -d' ' -f2)
  halo=$(grep -o "halo exchanges [0-9.e+-]* ms" <<<"$out" | cut -d' ' -f3)
  red=$(grep -o "reductions [0-9.e+-]* ms" <<<"$out" | cut -d' ' -f2)
  bytes=$(grep -o "([0-9.e+-]* MB received" <<<"$out" | tr -d '(' | cut -d' ' -f1)
  gather=$(grep -o "observation [0-9.e+-]* ms" <<<"$out" | cut -d' ' -f2)
  printf "%9s particles  %d x %d  %8.3f ms/step  %.3g particle-steps/s  halo %s ms  reductions %s ms  %s MB/step  gather %s ms\n" \
    "$n" "$ranks" "$threads" "$(echo "$wall * 1000 / $steps" | bc -l)" "$rate" "${halo:--}" "${red:--}" "${bytes:--}" "${gather:--}"
  [ -n "$rate" ] || echo "$out" | tail -5
}
if [ "$what" = strong ] || [ "$what" = all ]; then
  echo "# strong scaling: the same beam (length 1 m) on more ranks"
  for size in "0.01 1000" "0.00464 100" "0.00215 10"; do
    set -- $size
    run 1 1 "$2" "$1" 1; run 1 2 "$2" "$1" 1; run 2 1 "$2" "$1" 1; run 4 1 "$2" "$1" 1
  done
fi
if [ "$what" = weak ] || [ "$what" = all ]; then
  echo "# weak scaling: about 10^5 particles per rank (the beam 1 m longer per rank)"
  run 1 1 100 0.00464 1; run 2 1 100 0.00464 2; run 4 1 100 0.00464 4
fi
