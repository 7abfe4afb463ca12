#!/bin/bash
# The roofline table of docs/performance.md: build/tlsph_bench on the 3D cantilever
# at about 10^4, 10^5 and 10^6 particles, the benchmark's rows (linear correction, nodal
# quadrature) and the scene defaults (quadratic correction, Taylor quadrature), on 1 and 2
# threads. Each line: particles, configuration, threads, particle-steps/s, the force passes'
# counted traffic per particle-step, the bandwidth it reaches and its share of a plain copy's.
# Usage: benchmarks/roofline.sh [sizes...]   (default 1e4 1e5 1e6; about 6 minutes on 2 cores,
# 10 GB of memory at 10^6)
set -u
cd "$(dirname "$0")/.."
BENCH=build/tlsph_bench
sizes=${*:-"1e4 1e5 1e6"}
for size in $sizes; do
  case $size in
    1e4) n=10000 steps=500 ;;
    1e5) n=100000 steps=50 ;;
    1e6) n=1000000 steps=10 ;;
    *) n=$size steps=20 ;;
  esac
  for config in "linear nodal" "quadratic taylor"; do
    set -- $config
    for threads in 1 2; do
      out=$(OMP_NUM_THREADS=$threads $BENCH --particles "$n" --steps "$steps" --correction "$1" \
        --quadrature "$2" 2>&1)
      particles=$(grep -o "^particles [0-9]*" <<<"$out" | cut -d' ' -f2)
      rate=$(grep -o "particle-steps/s [0-9.e+-]*" <<<"$out" | cut -d' ' -f2)
      kb=$(grep -o "= [0-9.e+-]* kB per particle-step" <<<"$out" | cut -d' ' -f2)
      gbs=$(grep -o "reached [0-9.e+-]* GB/s" <<<"$out" | cut -d' ' -f2)
      share=$(grep -o "= [0-9.e+-]* % of a plain copy's [0-9.e+-]* GB/s" <<<"$out" |
        awk '{print $2 " % of " $8}')
      printf "%8s particles  %-9s %-6s %d thr  %.3g particle-steps/s  %5.2f kB/step  %5.1f GB/s  %s GB/s\n" \
        "$particles" "$1" "$2" "$threads" "$rate" "$kb" "$gbs" "$share"
      [ -n "$rate" ] || echo "$out" | tail -5
    done
  done
done
