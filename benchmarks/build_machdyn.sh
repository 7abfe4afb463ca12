#!/bin/bash
# Builds LAMMPS with the MACHDYN package (pair smd/tlsph) for benchmarks/machdyn_side_by_side.sh.
# Not a tlsph dependency: only the side-by-side benchmark uses it.
# Debian's `lammps` package is built without MACHDYN, so this takes the source Debian ships
# (LAMMPS stable 7 Jan 2022, the bookworm package 20220106.git7586adbb6a+ds1, MACHDYN included),
# checks it against the checksum in Debian's .dsc, and builds only the core and MACHDYN with MPI
# and the flags tlsph uses (-O3 -march=native). About 2.5 minutes on the 2-core Intel development
# machine, an 80 MB download.
# Usage: benchmarks/build_machdyn.sh [DIR]   (default build/machdyn; prints the lmp binary's path)
# Needs: cmake, g++, libeigen3-dev, libopenmpi-dev (all installed by scripts/setup.sh), curl.
set -eu
cd "$(dirname "$0")/.."
dir=$(readlink -f "${1:-build/machdyn}")
tarball=lammps_20220106.git7586adbb6a+ds1.orig.tar.xz
url=http://deb.debian.org/debian/pool/main/l/lammps/$tarball
sha256=65146c615ad24d8b8bc64f4e05e86226a7f1fdb45c0b5ea9416562b9f3863082  # from Debian's .dsc
mkdir -p "$dir"
if [ -x "$dir/build/lmp" ]; then
  echo "$dir/build/lmp"
  exit 0
fi
if ! echo "$sha256  $dir/$tarball" | sha256sum -c --status 2>/dev/null; then
  echo "downloading $url" >&2
  curl -fsSL -o "$dir/$tarball.part" "$url"
  mv "$dir/$tarball.part" "$dir/$tarball"
  echo "$sha256  $dir/$tarball" | sha256sum -c --status ||
    { echo "checksum mismatch for $dir/$tarball" >&2; exit 1; }
fi
rm -rf "$dir/src" && mkdir -p "$dir/src"
tar -xJf "$dir/$tarball" -C "$dir/src" --strip-components=1
[ -d "$dir/src/src/MACHDYN" ] || { echo "no MACHDYN package in $tarball" >&2; exit 1; }
cmake -S "$dir/src/cmake" -B "$dir/build" -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_CXX_FLAGS_RELEASE="-O3 -march=native -DNDEBUG" -DPKG_MACHDYN=yes \
  -DDOWNLOAD_EIGEN3=no -DBUILD_MPI=yes -DBUILD_OMP=yes >"$dir/cmake.log" 2>&1 ||
  { tail -20 "$dir/cmake.log" >&2; exit 1; }
cmake --build "$dir/build" -j "$(nproc)" >"$dir/build.log" 2>&1 ||
  { tail -20 "$dir/build.log" >&2; exit 1; }
"$dir/build/lmp" -h | grep -q MACHDYN || { echo "lmp built without MACHDYN" >&2; exit 1; }
echo "$dir/build/lmp"
