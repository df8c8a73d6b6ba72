#!/usr/bin/env bash
# The README's second command (and what CI runs): install what is missing,
# build everything, run every test through CTest, then fuzz briefly and run
# the fast tests under sanitizers. Each step prints its time.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DBSPRT_BUILD_BENCH=OFF
cmake --build build -j "$(nproc)"
ctest --test-dir build --output-on-failure -j "$(nproc)"
echo "test.sh: build + tests took ${SECONDS}s"
# Short bounded fuzzing (every harness in fuzz/, 20 s each) and the fast tests
# under ASan+UBSan; scripts/fuzz.sh 3600 and SANITIZE_ALL=1 scripts/sanitize.sh run them long.
t=$SECONDS; scripts/sanitize.sh; echo "test.sh: sanitizers took $((SECONDS - t))s"
t=$SECONDS; scripts/fuzz.sh 20; echo "test.sh: fuzzing took $((SECONDS - t))s"
