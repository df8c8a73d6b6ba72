#!/usr/bin/env bash
# CTest "consumer_project": installs the build tree into a temporary prefix,
# builds examples/consumer against it with find_package(bsprt), and runs it on
# a shared mesh. Usage: consumer_test.sh SOURCE_DIR BUILD_DIR MESH
set -euo pipefail
src=$1 build=$2 mesh=$3
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cmake --install "$build" --prefix "$tmp/prefix" > "$tmp/install.log"
# The installed headers must stand alone: none includes CGAL, Embree, TBB or OpenMesh.
if grep -rnE '#include *<(CGAL|embree|tbb|oneapi|OpenMesh)' "$tmp/prefix/include/bsprt"; then
  echo "consumer_test: an installed public header includes a dependency's header" >&2
  exit 1
fi
cmake -S "$src/examples/consumer" -B "$tmp/consumer" -G Ninja -DCMAKE_BUILD_TYPE=Release \
      -DCMAKE_PREFIX_PATH="$tmp/prefix" > "$tmp/configure.log"
cmake --build "$tmp/consumer" > "$tmp/build.log"
"$tmp/consumer/consumer" "$mesh"
"$tmp/prefix/bin/bsprt" info "$mesh" > /dev/null
# The installed Python module must load the installed libbsprt from this
# prefix, not one in /usr/local (its RPATH was fixed there; review of 2026-12-07).
pydir=$(find "$tmp/prefix" -type d -name dist-packages | head -1)
if ls "$build"/python/bsprt/_bsprt*.so > /dev/null 2>&1 && { [ -z "$pydir" ] || [ ! -d "$pydir/bsprt" ]; }; then
  echo "consumer_test: the build has the Python module but the install does not" >&2
  exit 1
fi
if [ -n "$pydir" ] && [ -d "$pydir/bsprt" ]; then
  env -u LD_LIBRARY_PATH PYTHONPATH="$pydir" /usr/bin/python3 -c "
import bsprt, os, sys
lib = [l.split()[-1] for l in open('/proc/self/maps') if 'libbsprt.so' in l]
assert lib and all(p.startswith(sys.argv[1]) for p in lib), lib
" "$tmp/prefix"
fi
