#!/bin/bash
# Side-by-side throughput of LAMMPS's MACHDYN (pair smd/tlsph) and build/tlsph_bench on the same
# 3D cantilever (benchmarks/bench_cantilever.cpp). Needs a LAMMPS built from source with
# the MACHDYN package (not a tlsph dependency; Debian's lammps package lacks it):
# benchmarks/build_machdyn.sh builds one from Debian's LAMMPS source and prints its path.
# Prints particle-steps/s = atoms x steps / loop time. Written from LAMMPS's documentation,
# examples and sources (cited below); numbers from it are in docs/performance.md.
# Usage: benchmarks/machdyn_side_by_side.sh LMP_BINARY [dx] [steps] [procs...]
#   e.g. benchmarks/machdyn_side_by_side.sh "$(benchmarks/build_machdyn.sh)" 0.0125 2000
#   defaults: dx 0.0125 (5,312 particles), steps 200, procs "1 2" (MACHDYN: MPI ranks, one
#   OpenMP thread each; tlsph: OpenMP threads, one process). The sizes in
#   docs/performance.md: 0.0125 2000 and 0.00625 200. Environment: MPIRUN (default mpirun), HG (both codes' hourglass coefficient,
#   default 10), CFL (default 0.3), PAIRED=1 (one core each, both codes at once; below),
#   ROUNDS=N (the codes in turn, N times, each tlsph rate against the MACHDYN runs either side of
#   it; below).
#
# Equal in both codes: the particles (cell-centred cubic lattice of spacing dx: an 80 x 8 x 8 body
# at dx 0.0125 plus ceil(2.1) = 3 clamp layers at x < 0 that never move), volume dx^3, density
# 1000, E = 1e7, nu = 0.3, gravity (0, 0, -1), the kernel support H = 2.1 dx (32 neighbours
# inside), the step count, no artificial viscosity, and one fixed time step of CFL dx / c with
# c = sqrt((K + 4G/3)/rho). tlsph adds the hourglass term's speed to c (src/method/TimeStep.hpp),
# so its dt is a little smaller; the table shows both. The cost of a step does not depend on dt.
# NOT equal: the material model. MACHDYN has no neo-Hookean model; its only elastic model is
# hypoelastic: *STRENGTH_LINEAR (deviatoric stress rate 2G d_dev) with *EOS_LINEAR (pressure rate
# K tr d), co-rotated by the polar decomposition of F, as in LAMMPS's rubber examples.
# (*LINEAR_DEFGRAD is parsed but stops with "only for debugging purposes and currently
# deactivated" in src/MACHDYN/pair_smd_tlsph.cpp.) Nor the hourglass term: MACHDYN's hg scales a
# pairwise spring on the error of F dX against dx by E; tlsph's alpha scales its energy penalty
# (--form ganzenmueller is the textbook form of MACHDYN's term; not timed here). The kernels
# differ (MACHDYN: spiky; tlsph: Wendland C2), MACHDYN visits each pair from both particles, and
# it evaluates its artificial viscosity term even at q1 = q2 = 0.
# The last column, the tip's u_z, only checks that both move the same scene: early on it is near
# -g t^2 / 2 with t = (steps + 1) dt in both (scale by the dt ratio); no accuracy comparison.
set -u
cd "$(dirname "$0")/.."
[ $# -ge 1 ] || { sed -n 8,12p "$0"; exit 2; }
LMP=$1; [[ $LMP == */* ]] && LMP=$(readlink -f "$LMP")
command -v "$LMP" >/dev/null || { echo "no LAMMPS binary at $1" >&2; exit 2; }
dx=${2:-0.0125}; steps=${3:-200}; shift $(($# < 3 ? $# : 3)); procs=${*:-1 2}
MPIRUN=${MPIRUN:-mpirun}; HG=${HG:-10}; CFL=${CFL:-0.3}; support=2.1
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1  # as benchmarks/scaling.sh
export OMPI_MCA_btl_vader_single_copy_mechanism=none
# Lattice counts as in bench_cantilever.cpp (lround, ceil) and the CFL step dt = CFL dx / c.
read -r nx ny layers dt < <(awk -v dx="$dx" -v s="$support" -v cfl="$CFL" 'BEGIN {
  E = 1e7; nu = 0.3; rho = 1000; lambda = E*nu/((1+nu)*(1-2*nu)); G = E/(2*(1+nu))
  l = int(s); if (l < s) l++
  printf "%d %d %d %.6g\n", int(1/dx + 0.5), int(0.1/dx + 0.5), l, cfl*dx/sqrt((lambda+2*G)/rho) }')
work=$(mktemp -d /tmp/machdyn_side_by_side.XXXXXX)

# The LAMMPS input, after examples/PACKAGES/machdyn/rubber_strip_pull/in.rubber_strip_pull (same
# commands in 2D) and rubber_rings_3d (3D, boundary m m m). LAMMPS's beam spans y, z in [0, 0.1],
# not [-0.05, 0.05]: the lattice origin then needs no offset, and a translation changes nothing.
cat >"$work/in.cantilever" <<'EOF'
dimension       3
units           si
boundary        m m m
atom_style      smd                 # per-atom volume, mass, kernel radius, reference position x0
atom_modify     map array           # required: smd/tlsph finds partners by atom ID
comm_modify     vel yes
newton          off                 # required by pair smd/tlsph
neighbor        ${dx} bin           # skin dx: displacements here stay far below it
neigh_modify    every 10 delay 0 check yes

variable        w equal ${ny}*${dx}
variable        xbody equal ${nx}*${dx}
variable        xclamp equal -${layers}*${dx}
variable        xlo equal -(${layers}+1)*${dx}
variable        xhi equal (${nx}+1)*${dx}
variable        lo equal -${dx}
variable        hi equal (${ny}+1)*${dx}
variable        xtip equal (${nx}-1)*${dx}
lattice         sc ${dx} origin 0.5 0.5 0.5     # points at (i + 1/2) dx: cell-centred
region          box block ${xlo} ${xhi} ${lo} ${hi} ${lo} ${hi} units box
create_box      1 box
region          body block 0 ${xbody} 0 ${w} 0 ${w} units box
region          clamp block ${xclamp} 0 0 ${w} 0 ${w} units box
create_atoms    1 region body       # create_atoms sets x0 = x and molecule 1 (atom_vec_smd.cpp)
create_atoms    1 region clamp
group           body region body
group           clamp region clamp
group           tlsph union body clamp  # pair smd/tlsph requires a group named tlsph
variable        vol equal ${dx}^3
variable        h equal ${support}*${dx}
set             group all volume ${vol}
set             group all smd/mass/density 1000   # mass = density x volume: set volume first
set             group all diameter ${h}   # kernel radius = radius_i + radius_j = diameter = H

# *COMMON rho0 E nu Q1 Q2 hg Cp (Q1, Q2: artificial viscosity, off; Cp: heat capacity, unused)
pair_style      smd/tlsph
pair_coeff      1 1 *COMMON 1000 1e7 0.3 0 0 ${hg} 1 &
                *STRENGTH_LINEAR &
                *EOS_LINEAR &
                *END

# The clamp is not integrated: it keeps x = x0 and v = 0, as tlsph's prescribed particles.
fix             integrate body smd/integrate_tlsph
fix             grav body gravity 1.0 vector 0 0 -1   # acceleration: force = rmass g
timestep        ${dt}               # fixed: no fix smd/adjust_dt

# The particle tlsph_bench reports (index nx - 1: tip, lowest y and z); its u_z.
region          tip block ${xtip} ${xbody} 0 ${dx} 0 ${dx} units box
group           tip region tip
variable        tipuz equal xcm(tip,z)-0.5*${dx}
thermo_style    custom step v_tipuz
run             1                   # warm-up, one step as tlsph_bench's (the setup's force call
                                    # only builds the reference partner lists)
run             ${steps}
EOF

echo "# dx $dx: ${nx}x${ny}x${ny} body + $layers clamp layers, $steps steps, hg = alpha = $HG;" \
  "MACHDYN logs in $work"
# PAIRED=1: one core each, both codes at the same time (each pinned with taskset to its own
# core), then again with the cores swapped: on a shared host whose speed drifts by tens of
# percent over minutes (seen on the Zen 4 development machine), the two codes then see the same
# host, and the ratio is measured within each run (tlsph, the faster, runs wholly inside
# MACHDYN's run). Needs 2 cores; the procs are ignored.
if [ "${PAIRED:-0}" = 1 ]; then
  command -v taskset >/dev/null || { echo "PAIRED=1 needs taskset (util-linux)" >&2; exit 2; }
  [ -x build/tlsph_bench ] || { echo "(no build/tlsph_bench: build tlsph to compare)"; exit 0; }
  [ "$(nproc)" -ge 2 ] || { echo "PAIRED=1 needs 2 cores, this machine has $(nproc)" >&2; exit 2; }
  extra=$(build/tlsph_bench --help | grep -q -- --no-stream && echo --no-stream)
  printf "%-18s %-9s %12s %-9s %12s %9s\n" config MACHDYN p-steps/s tlsph p-steps/s tlsph/MD
  for config in "bench-default" "quadratic-taylor"; do
    args="--dx $dx --steps $steps --alpha $HG $extra"
    [ "$config" = quadratic-taylor ] && args="$args --correction quadratic --quadrature taylor"
    for swap in 0 1; do
      cm=$swap; ct=$((1 - swap)); log=$work/log.paired.$config.$swap
      # one rank without mpirun (MPI's singleton start), pinned like the tlsph process
      OMP_NUM_THREADS=1 taskset -c "$cm" "$LMP" -in "$work/in.cantilever" -log "$log" \
        -screen none -var dx "$dx" -var nx "$nx" -var ny "$ny" -var layers "$layers" \
        -var support "$support" -var hg "$HG" -var dt "$dt" -var steps "$steps" \
        >"$work/out.paired" 2>&1 &
      out=$(OMP_NUM_THREADS=1 taskset -c "$ct" build/tlsph_bench $args 2>&1)
      wait
      md=$(grep -s "^Loop time of" "$log" | tail -1 | awk '{print $12 * $9 / $4}')
      rate=$(grep -o "particle-steps/s [0-9.e+-]*" <<<"$out" | cut -d' ' -f2)
      [ -n "$md" ] && [ -n "$rate" ] || { echo "paired run failed:"; tail -n 5 "$log"; continue; }
      ratio=$(awk -v a="$rate" -v b="$md" 'BEGIN {printf "%.2f", a / b}')
      printf "%-18s %-9s %12.4g %-9s %12.4g %9s\n" "$config" "core $cm" "$md" "core $ct" \
        "$rate" "$ratio"
    done
  done
  exit 0
fi
# ROUNDS=N: for runs that need every core (two ranks, two threads), where PAIRED cannot be used:
# MACHDYN, tlsph, MACHDYN, tlsph, ..., MACHDYN. Each tlsph rate is divided by the mean of the two
# MACHDYN runs either side of it, and the median of the N ratios is printed. tlsph runs its
# benchmark REPEAT times back to back in each turn (default: as many as fill MACHDYN's first
# run's wall time, at most 20), so that both codes sample the host over about the same minutes.
if [ -n "${ROUNDS:-}" ]; then
  [ -x build/tlsph_bench ] || { echo "(no build/tlsph_bench: build tlsph to compare)"; exit 0; }
  extra=$(build/tlsph_bench --help | grep -q -- --no-stream && echo --no-stream)
  machdyn_rate() {  # $1 ranks; prints particle-steps/s and the loop's wall time
    local log=$work/log.rounds
    OMP_NUM_THREADS=1 $MPIRUN -np "$1" "$LMP" -in "$work/in.cantilever" -log "$log" \
      -screen none -var dx "$dx" -var nx "$nx" -var ny "$ny" -var layers "$layers" \
      -var support "$support" -var hg "$HG" -var dt "$dt" -var steps "$steps" \
      >"$work/out.rounds" 2>&1
    grep -s "^Loop time of" "$log" | tail -1 | awk '{print $12 * $9 / $4, $4}'
  }
  tlsph_rate() {  # $1 threads, $2 repeats, rest: bench arguments; prints the mean rate and wall
    local threads=$1 repeat=$2; shift 2
    for ((r = 0; r < repeat; ++r)); do
      OMP_NUM_THREADS=$threads build/tlsph_bench "$@" 2>&1 |
        grep -o "wall [0-9.e+-]* s, particle-steps/s [0-9.e+-]*" | awk '{print $5, $2}'
    done | awk '{n++; sum += $1; wall += $2} END {if (n) print sum / n, wall / n}'
  }
  printf "%-18s %5s %5s %12s %12s %12s %9s\n" config procs round "MACHDYN" "tlsph" "MACHDYN" \
    tlsph/MD
  for config in "bench-default" "quadratic-taylor"; do
    args="--dx $dx --steps $steps --alpha $HG $extra"
    [ "$config" = quadratic-taylor ] && args="$args --correction quadratic --quadrature taylor"
    for p in $procs; do
      read -r before mdwall < <(machdyn_rate "$p")
      [ -n "${before:-}" ] || { echo "MACHDYN on $p ranks failed:"; tail -n 5 "$work/out.rounds"; exit 1; }
      repeat=${REPEAT:-}
      ratios=()
      for ((round = 1; round <= ROUNDS; ++round)); do
        if [ -z "$repeat" ]; then  # one run to learn its wall time
          read -r rate wall < <(tlsph_rate "$p" 1 $args)
          repeat=$(awk -v m="$mdwall" -v t="$wall" 'BEGIN {r = int(m / t + 0.5); print r < 1 ? 1 : (r > 20 ? 20 : r)}')
        fi
        read -r rate wall < <(tlsph_rate "$p" "$repeat" $args)
        read -r after mdwall < <(machdyn_rate "$p")
        [ -n "${rate:-}" ] && [ -n "${after:-}" ] || { echo "round $round failed"; exit 1; }
        ratio=$(awk -v a="$rate" -v b="$before" -v c="$after" 'BEGIN {printf "%.2f", 2 * a / (b + c)}')
        ratios+=("$ratio")
        printf "%-18s %5s %5s %12.4g %12.4g %12.4g %9s\n" "$config" "$p" "$round" "$before" \
          "$rate" "$after" "$ratio"
        before=$after
      done
      printf "%-18s %5s %5s  median of %d ratios (tlsph %d x %d steps per turn): %s\n" "$config" \
        "$p" - "$ROUNDS" "$repeat" "$steps" \
        "$(printf "%s\n" "${ratios[@]}" | sort -g | awk '{v[NR] = $1} END {print NR % 2 ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2}')"
    done
  done
  exit 0
fi
row="%-8s %-18s %5s %9s %6.1f %10.4g %9.3f %12.4g %9s %12.4g\n"
printf "%-8s %-18s %5s %9s %6s %10s %9s %12s %9s %12s\n" code config procs particles neighb \
  "dt [s]" "wall [s]" "p-steps/s" "tlsph/MD" "tip u_z [m]"
declare -A machdyn
for p in $procs; do
  out=$work/out.$p; log=$work/log.$p
  OMP_NUM_THREADS=1 $MPIRUN -np "$p" "$LMP" -in "$work/in.cantilever" -log "$log" -screen none \
    -var dx "$dx" -var nx "$nx" -var ny "$ny" -var layers "$layers" -var support "$support" \
    -var hg "$HG" -var dt "$dt" -var steps "$steps" >"$out" 2>&1
  # "Loop time of T on P procs for N steps with A atoms": the last run is the timed one.
  T=; read -r T P N A < <(grep -s "^Loop time of" "$log" | tail -1 | awk '{print $4, $6, $9, $12}')
  if [ -z "$T" ]; then echo "MACHDYN on $p ranks failed:"; tail -n 5 "$out" "$log"; continue; fi
  nb=$(grep "average # of neighbors/particle in group tlsph" "$log" | tail -1 | awk '{print $NF}')
  uz=$(awk '/^Loop time of/ {print last} {last = $0}' "$log" | tail -1 | awk '{print $2}')
  machdyn[$p]=$(awk -v a="$A" -v n="$N" -v t="$T" 'BEGIN {print a*n/t}')
  printf "$row" MACHDYN linear-hypoelastic "${P}r" "$A" "${nb:-0}" "$dt" "$T" "${machdyn[$p]}" - \
    "${uz:-0}"
  grep -q "deleting particle" "$out" && echo "  warning: MACHDYN deleted particles (det F out of" \
    "range): the step is unstable for it, lower CFL"
done

[ -x build/tlsph_bench ] || { echo "(no build/tlsph_bench: build tlsph to compare)"; exit 0; }
# Skip the bench's copy-bandwidth measurement (roofline) where it has one: not part of the step.
extra=$(build/tlsph_bench --help | grep -q -- --no-stream && echo --no-stream)
for config in "bench-default" "quadratic-taylor"; do
  args="--dx $dx --steps $steps --alpha $HG $extra"
  [ "$config" = quadratic-taylor ] && args="$args --correction quadratic --quadrature taylor"
  for p in $procs; do
    out=$(OMP_NUM_THREADS=$p build/tlsph_bench $args 2>&1)
    n=$(grep -o "^particles [0-9]*" <<<"$out" | cut -d' ' -f2)
    nb=$(grep -o "mean neighbours [0-9.e+-]*" <<<"$out" | cut -d' ' -f3)
    tdt=$(grep -o ", dt [0-9.e+-]*" <<<"$out" | cut -d' ' -f3)
    wall=$(grep -o "wall [0-9.e+-]* s" <<<"$out" | cut -d' ' -f2)
    rate=$(grep -o "particle-steps/s [0-9.e+-]*" <<<"$out" | cut -d' ' -f2)
    uz=$(grep -o "tip u_z [0-9.e+-]*" <<<"$out" | cut -d' ' -f3)
    [ -n "$rate" ] || { echo "tlsph_bench $args failed:"; tail -n 5 <<<"$out"; continue; }
    ratio=$(awk -v a="$rate" -v b="${machdyn[$p]:-}" 'BEGIN {print b ? sprintf("%.2f", a/b) : "-"}')
    printf "$row" tlsph "$config" "${p}t" "$n" "$nb" "$tdt" "$wall" "$rate" "$ratio" "$uz"
  done
done
