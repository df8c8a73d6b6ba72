#!/usr/bin/env bash
# The README's first command: install what is missing, build in Release, and
# render the embedded default scene to out/default.png (exact BSP built in
# memory, certified float traversal; BSPRT_DEMO_ACCEL=kd|embree|... to compare).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build build --target bsprt -j "$(nproc)"
mkdir -p out
build/apps/bsprt render -o out/default.png --size 1024 768 --accel "${BSPRT_DEMO_ACCEL:-bsp}" --stats
echo "demo: wrote out/default.png"
