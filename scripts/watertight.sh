#!/usr/bin/env bash
# Watertightness, long: 10^8 rays from inside closed meshes (icospheres and
# tori at the origin and at 1e5, a grid box, a bicone) per mode (kd, bsp,
# bsp-float, and Embree measured), i.e. tests/test_watertight_inside.cpp
# with BSPRT_WATERTIGHT_RAYS=N (CI runs 10^6). Prints leaks per mode as a
# Markdown table (also appended to build/robustness-watertight.md).
#   scripts/watertight.sh            # 10^8 rays per mode
#   scripts/watertight.sh 1e7        # fewer
set -euo pipefail
rays=${1:-1e8}
cd "$(dirname "$0")/.."
build=${BSPRT_BUILD_DIR:-build}
scripts/install-deps.sh
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$build" --target test_stiff -j "$(nproc)"
report="$build/robustness-watertight.md"
echo "| closed mesh | rays per mode | kd | bsp-float | bsp | bsp-top-float | bsp-top | embree |" > "$report"
echo "| --- | --- | --- | --- | --- | --- | --- | --- |" >> "$report"
BSPRT_WATERTIGHT_RAYS="$rays" BSPRT_ROBUSTNESS_REPORT="$report" \
  "$build/tests/test_stiff" "[watertight]"
cat "$report"
