#!/usr/bin/env bash
# Configures build-fuzz/: clang with ASan + UBSan + libFuzzer coverage on every
# library, tests on. One instrumented build serves both scripts/fuzz.sh (the
# harnesses) and scripts/sanitize.sh (the fast tests under ASan+UBSan), so CI
# compiles the project twice (gcc Release + this), not three times.
set -euo pipefail
cd "$(dirname "$0")/.."
# -O1 with line tables only: readable sanitizer stacks at a fraction of the
# compile time of -O2 -g on the CGAL-heavy files.
CXX=clang++ cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=Sanitize \
  -DCMAKE_CXX_FLAGS_SANITIZE="-O1 -gline-tables-only" \
  -DBSPRT_BUILD_FUZZERS=ON -DBUILD_TESTING=ON -DBSPRT_BUILD_BENCH=OFF -DBSPRT_BUILD_PYTHON=OFF >/dev/null
