#!/usr/bin/env bash
# Installs every Debian package bsprt needs that is not installed yet (apt-get
# only). Safe to run again: it does nothing when all packages are present.
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config
  libcgal-dev libgmp-dev libmpfr-dev libboost-dev   # exact kernels (CGAL) and what CGAL needs
  libeigen3-dev libopenmesh-dev                     # vectors, mesh IO
  libtbb-dev libcli11-dev libfmt-dev libstb-dev     # parallelism, CLI, formatting, PNG
  libembree-dev                                     # Embree 3: benchmark peer and test oracle
  nlohmann-json3-dev                                # camera files (JSON)
  catch2 libbenchmark-dev                           # tests (Catch2 v2) and micro-benchmarks
  clang libclang-rt-dev                             # libFuzzer harnesses and sanitizers
  gnuplot-nox                                       # plots in docs/performance.md (scripts/docs.sh)
  pybind11-dev python3-dev python3-numpy            # the Python module (python/)
  python3-pytest python3-matplotlib                 # its tests and the docs/api.md example plot
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi
echo "install-deps: installing ${missing[*]}"
sudo=""
if [ "$(id -u)" -ne 0 ]; then sudo="sudo"; fi
$sudo apt-get update -q
DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -q --no-install-recommends "${missing[@]}"
