#!/usr/bin/env bash
# One entry point for a fresh machine: installs the Debian packages that are missing,
# configures and builds (Release), then does what was asked.
#
#   scripts/setup.sh build     install + build (default)
#   scripts/setup.sh test      install + build + run the test suite (ctest)
#   scripts/setup.sh example   install + build + run the main example scene
#
# Environment: BUILD_DIR (default build), JOBS (default: number of cores).
set -euo pipefail

cd "$(dirname "${BASH_SOURCE[0]}")/.."
action="${1:-build}"
build_dir="${BUILD_DIR:-build}"
jobs="${JOBS:-$(nproc)}"

packages=(cmake make g++ libeigen3-dev libboost-program-options-dev libvtk9-dev
  libgtest-dev googletest)

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

cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$build_dir" -j "$jobs"

case "$action" in
  build) ;;
  test)
    ctest --test-dir "$build_dir" --output-on-failure -j "$jobs"
    ;;
  example)
    # The 3D cantilever under self-weight (DESIGN.md section 6), run to static equilibrium.
    "$build_dir/tlsph" run examples/cantilever.ini --output.directory=output/cantilever
    echo "setup: open $(pwd)/output/cantilever/cantilever.pvd in ParaView"
    ;;
  *)
    echo "usage: scripts/setup.sh [build|test|example]" >&2
    exit 2
    ;;
esac
