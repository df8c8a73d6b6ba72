#!/usr/bin/env bash
# CTest "public_headers": every header of include/bsprt/ compiles on its own
# with only bsprt's include folders, and nothing it reaches, transitively, is a
# CGAL, Embree, TBB, OpenMesh, GMP or Boost header (the C++ preprocessor lists
# every file it opens). Usage: public_headers_test.sh SOURCE_DIR BUILD_DIR CXX
set -euo pipefail
src=$1 build=$2 cxx=$3
fail=0
for h in "$src"/include/bsprt/*.h; do
  deps=$(echo "#include \"bsprt/$(basename "$h")\"" | "$cxx" -std=c++20 -M -I "$src/include" -I "$build/include" -x c++ -) || { echo "FAIL: $h does not compile alone"; fail=1; continue; }
  if bad=$(echo "$deps" | tr ' ' '\n' | grep -iE '/(CGAL|embree3?|tbb|oneapi|OpenMesh|gmp|mpfr|boost)[/.]'); then
    echo "FAIL: $(basename "$h") reaches: $bad"
    fail=1
  fi
  echo "#include \"bsprt/$(basename "$h")\"" | "$cxx" -std=c++20 -fsyntax-only -Wall -Wextra -Werror -I "$src/include" -I "$build/include" -x c++ - || fail=1
done
[ $fail -eq 0 ] && echo "public headers: $(ls "$src"/include/bsprt/*.h | wc -l) headers, self-contained, no dependency header reachable"
exit $fail
