#!/usr/bin/env bash
# The README's first command: install what is missing, build in Release,
# install the library, the CLI and the Python module (cmake --install, prefix
# BSPRT_PREFIX, default /usr/local), and render the embedded default scene to
# out/default.png (exact BSP built in memory, certified float traversal;
# BSPRT_DEMO_ACCEL=kd|embree|... to compare).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build build --target bsprt bsprt_lib bsprt_python -j "$(nproc)"
cmake --install build --prefix "${BSPRT_PREFIX:-/usr/local}" > /dev/null
ldconfig 2>/dev/null || true
/usr/bin/python3 -c "import bsprt; print('demo: python3 -c \"import bsprt\" works, bsprt', bsprt.__version__)"
mkdir -p out
build/apps/bsprt render -o out/default.png --size 1024 768 --accel "${BSPRT_DEMO_ACCEL:-bsp}" --stats
echo "demo: wrote out/default.png"
