#!/usr/bin/env bash
# Builds the libFuzzer harnesses (clang, ASan+UBSan) in build-fuzz/ and runs
# each for SECONDS (default 60) on a copy of its seed corpus in fuzz/corpus/.
#   scripts/fuzz.sh            # 60 s each (what CI runs is scripts/test.sh's short pass)
#   scripts/fuzz.sh 3600       # an hour each, by hand
# A finding leaves a crash-* file in build-fuzz/findings/ and exits non-zero:
# turn it into a named regression test in tests/ before fixing it.
set -euo pipefail
secs=${1:-60}
cd "$(dirname "$0")/.."
scripts/install-deps.sh
scripts/configure-instrumented.sh
fuzzers=$(sed -n 's/^bsprt_add_fuzzer(\([a-z_]*\).*/\1/p' fuzz/CMakeLists.txt)
cmake --build build-fuzz --target $fuzzers -j "$(nproc)"
mkdir -p build-fuzz/findings
status=0
for f in $fuzzers; do
  corpus=fuzz/corpus/${f#fuzz_}
  work=$(mktemp -d)
  [ -d "$corpus" ] && cp -r "$corpus"/. "$work"/
  echo "fuzz: $f for ${secs}s"
  if ! build-fuzz/fuzz/$f -max_total_time="$secs" -rss_limit_mb=4096 -print_final_stats=0 \
       -artifact_prefix=build-fuzz/findings/$f- "$work" 2> build-fuzz/findings/$f.log; then
    echo "fuzz: $f FOUND A PROBLEM (see build-fuzz/findings/$f.log)"; tail -30 build-fuzz/findings/$f.log
    status=1
  else
    grep -E "^#[0-9]+ *DONE" build-fuzz/findings/$f.log | tail -1 || true
  fi
  rm -rf "$work"
done
exit $status
