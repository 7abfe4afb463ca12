#!/usr/bin/env bash
# One entry point for a fresh machine: installs the Debian packages that are missing,
# configures and builds (Release), then does what was asked.
#
#   scripts/setup.sh build     install + build (default)
#   scripts/setup.sh test      install + build + run the test suite (ctest)
#   scripts/setup.sh example   install + build the program + run the main example scene
#   scripts/setup.sh validate  install (+ numpy, matplotlib) + build + run the full validation
#                              ladder (validation/run.py, ~30 min on 2 cores): validation/report/
#   scripts/setup.sh stability install (+ numpy, matplotlib) + build + run the stability map
#                              (validation/stability.py, ~15-25 min on 2 cores):
#                              validation/report/stability.md
#
# Environment: BUILD_DIR (default build), JOBS (default: number of cores).
set -euo pipefail

cd "$(dirname "${BASH_SOURCE[0]}")/.."
action="${1:-build}"
build_dir="${BUILD_DIR:-build}"
jobs="${JOBS:-$(nproc)}"

packages=(cmake make g++ libeigen3-dev libboost-program-options-dev libvtk9-dev libsuitesparse-dev libopenblas0-pthread libspectra-dev libmetis-dev libopenmpi-dev openmpi-bin
  libgtest-dev googletest python3 libgmsh-dev gmsh)
# The validation report's plots need numpy and matplotlib (the quick check under ctest does not;
# the FEM VTU self-test under ctest needs numpy).
if [ "$action" = test ]; then
  packages+=(python3-numpy)
fi
if [ "$action" = validate ] || [ "$action" = stability ]; then
  packages+=(python3-numpy python3-matplotlib)
fi
# The FEM references of the validation (validation/fem.py) are computed with CalculiX.
if [ "$action" = validate ]; then
  packages+=(calculix-ccx)
fi
# The scene-parser fuzzer is built with clang's libFuzzer.
if [ "$action" = fuzz ]; then
  packages+=(clang libclang-rt-14-dev)
fi

missing=()
for pkg in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$pkg")
  fi
done
if ((${#missing[@]})); then
  echo "setup: installing missing Debian packages: ${missing[*]}"
  sudo_cmd=()
  if [ "$(id -u)" -ne 0 ]; then sudo_cmd=(sudo); fi
  "${sudo_cmd[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq "${missing[@]}" >/dev/null
fi

if [ "$action" = sanitize ]; then
  # The fast test suite (without the validation label) built with AddressSanitizer and
  # UndefinedBehaviorSanitizer, in its own build directory. The MPI tests (label mpi) are left
  # out: Open MPI's own allocations at exit are reported as leaks. libgmsh's own leaks are
  # suppressed (tests/lsan.supp).
  build_dir="${BUILD_DIR:-build-sanitize}"
  cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DTLSPH_SANITIZE=ON >/dev/null
  cmake --build "$build_dir" -j "$jobs"
  LSAN_OPTIONS="suppressions=$PWD/tests/lsan.supp" \
    ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1 \
    ctest --test-dir "$build_dir" --output-on-failure -j "$jobs" -LE 'validation|mpi'
  exit 0
fi
if [ "$action" = fuzz ]; then
  # The scene parser under libFuzzer for FUZZ_SECONDS (default 60) from the example and
  # validation scenes; a crashing input is written to fuzz-findings/ (make it a regression
  # test in tests/fuzz-regressions/).
  build_dir="${BUILD_DIR:-build-fuzz}"
  cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++ \
    -DTLSPH_FUZZ=ON -DTLSPH_OPENMP=OFF -DTLSPH_BUILD_TESTS=OFF >/dev/null
  cmake --build "$build_dir" -j "$jobs" --target tlsph_fuzz_scene
  corpus="$build_dir/fuzz-corpus"
  mkdir -p "$corpus" fuzz-findings
  cp examples/*.ini validation/scenes/*.ini tests/fuzz-regressions/*.ini "$corpus"/ 2>/dev/null || true
  "$build_dir/tlsph_fuzz_scene" "$corpus" -max_total_time="${FUZZ_SECONDS:-60}" -timeout=10 \
    -rss_limit_mb=2048 -artifact_prefix=fuzz-findings/ -print_final_stats=1
  exit 0
fi

cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=Release >/dev/null
if [ "$action" = example ]; then
  # The example runs the program only: the test programs are not needed for it.
  cmake --build "$build_dir" -j "$jobs" --target tlsph
else
  cmake --build "$build_dir" -j "$jobs"
fi

case "$action" in
  build) ;;
  test)
    ctest --test-dir "$build_dir" --output-on-failure -j "$jobs"
    ;;
  example)
    # The 3D cantilever under self-weight (docs/method.md section 6), run to static equilibrium.
    "$build_dir/tlsph" run examples/cantilever.ini --output.directory=output/cantilever --overwrite
    echo "setup: open $(pwd)/output/cantilever/cantilever.pvd in ParaView"
    ;;
  validate)
    # Every reference problem at its resolution ladder plus the sensitivity studies; writes
    # validation/report/ (README.md, results.json, plots). Extra arguments go to the runner.
    shift || true
    /usr/bin/python3 validation/run.py --build-dir "$build_dir" "$@"
    ;;
  stability)
    # The stability map: each case of validation/stability/ at the default time-step rule and
    # swept in [time] cfl up to its measured limit; writes validation/report/stability.md,
    # stability.json and the stability_*.png plots. Extra arguments go to the runner.
    shift || true
    /usr/bin/python3 validation/stability.py --build-dir "$build_dir" "$@"
    ;;
  *)
    echo "usage: scripts/setup.sh [build|test|example|validate|stability|sanitize|fuzz]" >&2
    exit 2
    ;;
esac
