#!/usr/bin/env bash
# Regenerates docs/performance.md, every figure and table in it (docs/perf/)
# and the gallery (docs/gallery/) from scratch: builds Release, runs
# `bsprt bench`, gnuplot, and `bsprt render`. About 15 minutes on 2 cores.
#   scripts/docs.sh                 # everything
#   BSPRT_DOCS_BUILD=dir BSPRT_DOCS_JOBS=1 scripts/docs.sh   # another build dir, fewer compile jobs
# Tunables (defaults sized for the 15-minute budget): COUNT, ERROR_COUNT,
# VERTEX_COUNT, SCALING_LEVELS, GALLERY_SIZE, GALLERY_SPP, RUNS.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$(pwd)
BUILD=${BSPRT_DOCS_BUILD:-build-docs}
SCENES=${BSPRT_SCENES_DIR:-$ROOT/../shared/scenes}
COUNT=${COUNT:-100000}
ERROR_COUNT=${ERROR_COUNT:-20000}
VERTEX_COUNT=${VERTEX_COUNT:-50000}
SCALING_LEVELS=${SCALING_LEVELS:-"3 4 5 6 7"}
GALLERY_SIZE=${GALLERY_SIZE:-"480 360"}
GALLERY_SPP=${GALLERY_SPP:-16}
RUNS=${RUNS:-3}  # bench timing rounds (each times every mode once; the fastest round counts)
PERF=docs/perf
GAL=docs/gallery
start=$(date +%s)

[ -n "${BSPRT_DOCS_SKIP_DEPS:-}" ] || scripts/install-deps.sh
cmake -S . -B "$BUILD" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$BUILD" --target bsprt -j "${BSPRT_DOCS_JOBS:-$(nproc)}"
BSPRT="$BUILD/apps/bsprt"
rm -rf "$PERF" "$GAL"
mkdir -p "$PERF" "$GAL"

# Meshes in ascending triangle count (all of ../shared/scenes/ that are meshes to benchmark).
MESHES=(suzanne.obj utah-teapot.obj happy-buddha-res4.ply stanford-bunny.obj armadillo-86k.obj stanford-dragon-100k.ply)
mesh_paths=()
for m in "${MESHES[@]}"; do mesh_paths+=("$SCENES/$m"); done
MODES=kd,kd-float,bsp,bsp-float,bsp-top,bsp-zero-eps,bvh8,bvh8-float,embree,embree-fast

# 1. Every mode, every mesh, four ray sets: speed, work, memory, error.
BENCH_CMD=(bench --runs "$RUNS" "${mesh_paths[@]}" --rays primary,random,vertex,edge --modes "$MODES"
           --count "$COUNT" --error-count "$ERROR_COUNT" -o "$PERF" --prefix bench)
"$BSPRT" "${BENCH_CMD[@]}" | tee "$PERF/bench.txt"
# 1b. The other meshes of ../shared/scenes/ (small, and the stiff ones), fewer rays.
#     stiff_test-nan.obj is left out: it loads only with --allow-nonfinite (hostile input).
SMALL=(cube.obj cornell_box.obj stiff_cube_with_fold.ply stiff_degenerated.obj stiff_planexy.off
       stiff_sliver_tet.ply stiff_truck.obj stiff_two-boxes-bad-self-union.ply)
small_paths=()
for m in "${SMALL[@]}"; do small_paths+=("$SCENES/$m"); done
SMALL_CMD=(bench --runs "$RUNS" "${small_paths[@]}" --rays primary,random,vertex,edge --modes "$MODES"
           --count 20000 --error-count 5000 -o "$PERF" --prefix small)
"$BSPRT" "${SMALL_CMD[@]}" | tee "$PERF/small.txt"
# 2. The key finding: rays aimed at the bunny's vertices, more of them.
VERTEX_CMD=(bench --runs "$RUNS" "$SCENES/stanford-bunny.obj" --rays vertex --modes "$MODES"
            --count "$VERTEX_COUNT" --error-count "$VERTEX_COUNT" --seed 7 -o "$PERF" --prefix vertex-bunny)
"$BSPRT" "${VERTEX_CMD[@]}" | tee "$PERF/vertex-bunny.txt"
# 3. Rays from inside closed generated icospheres (every ray must hit: a miss is a leak).
INSIDE_CMD=(bench --runs "$RUNS" icosphere:4 icosphere:6 --rays inside,vertex --modes "$MODES" --count "$COUNT"
            --error-count "$ERROR_COUNT" -o "$PERF" --prefix inside)
"$BSPRT" "${INSIDE_CMD[@]}" | tee "$PERF/inside.txt"
# 3b. Every triangle listed twice, the copy with reversed winding (issue #23): each hit ties with its copy.
TWINS_CMD=(bench --runs "$RUNS" "twin:$SCENES/utah-teapot.obj" "twin:$SCENES/stanford-bunny.obj" --rays primary,random,vertex,edge
           --modes kd,kd-float,bsp,bsp-float,embree --count "$COUNT" --error-count "$ERROR_COUNT" -o "$PERF"
           --prefix twins)
"$BSPRT" "${TWINS_CMD[@]}" | tee "$PERF/twins.txt"
# 4. Scaling: generated icospheres and the full dragon (the other meshes' random-ray rows come
#    from steps 1 and 5).
scaling_scenes=()
for l in $SCALING_LEVELS; do scaling_scenes+=("icosphere:$l"); done
scaling_scenes+=("$SCENES/stanford-dragon-871k.ply")
SCALING_CMD=(bench --runs "$RUNS" "${scaling_scenes[@]}" --rays random --modes kd,bsp,embree --count 65536 --error-count 0
             -o "$PERF" --prefix scaling)
"$BSPRT" "${SCALING_CMD[@]}" | tee "$PERF/scaling.txt"

# 5. Plots.
# The paper's regime: architectural scenes seen from inside (bench/cameras.json).
INTERIOR_CMD=(bench --runs "$RUNS" "$SCENES/sponza.obj" "$SCENES/conference-331k.obj" --cameras bench/cameras.json
              --rays primary,random,vertex,edge --modes "$MODES" --count "$COUNT" --error-count "$ERROR_COUNT"
              -o "$PERF" --prefix interior)
"$BSPRT" "${INTERIOR_CMD[@]}" | tee "$PERF/interior.txt"

gnuplot -e "dir='$PERF'; rays='vertex'" scripts/plot_error.gp
gnuplot -e "dir='$PERF'; rays='edge'" scripts/plot_error.gp
gnuplot -e "dir='$PERF'" scripts/plot_scaling.gp

# 6. Gallery and path-tracing speed per bounce: kd vs bsp (vs embree), trees built once.
GALLERY=(stanford-bunny.obj stanford-dragon-100k.ply armadillo-86k.obj happy-buddha-res4.ply sponza.obj conference-331k.obj)
# Scenes seen from inside get their camera from bench/cameras.json; the scans are framed.
declare -A CAMERA_OF=([sponza.obj]=sponza-atrium [conference-331k.obj]=conference-room)
read -r GW GH <<<"$GALLERY_SIZE"
for m in "${GALLERY[@]}"; do
  s="${m%.*}"
  cam=()
  [ -n "${CAMERA_OF[$m]:-}" ] && cam=(--camera "bench/cameras.json:${CAMERA_OF[$m]}")
  for a in kd bsp; do
    "$BSPRT" build "$SCENES/$m" --accel "$a" -o "$PERF/$s.$a.tree" >/dev/null
    "$BSPRT" render "$SCENES/$m" "${cam[@]}" --accel "$a" --tree "$PERF/$s.$a.tree" --mode path --size "$GW" "$GH" \
      --spp "$GALLERY_SPP" -o "$GAL/$s-path-$a.png" --json "$PERF/$s-path-$a.json" >/dev/null
    # Work per ray by bounce, counted on a smaller render of the same view (counting slows the timed trace).
    "$BSPRT" render "$SCENES/$m" "${cam[@]}" --accel "$a" --tree "$PERF/$s.$a.tree" --mode path --size 160 120 \
      --spp 4 --stats -o "$PERF/$s-path-$a-counts.png" --json "$PERF/$s-path-$a-counts.json" >/dev/null
    rm -f "$PERF/$s-path-$a-counts.png"
    "$BSPRT" render "$SCENES/$m" "${cam[@]}" --accel "$a" --tree "$PERF/$s.$a.tree" --mode heat --heat-metric tests \
      --size "$GW" "$GH" -o "$GAL/$s-heat-tests-$a.png" >/dev/null
  done
  "$BSPRT" render "$SCENES/$m" "${cam[@]}" --accel embree --mode path --size "$GW" "$GH" --spp "$GALLERY_SPP" \
    -o "$PERF/$s-path-embree.png" --json "$PERF/$s-path-embree.json" >/dev/null
  rm -f "$PERF/$s.kd.tree" "$PERF/$s.bsp.tree" "$PERF/$s-path-embree.png"
done

# 7. docs/performance.md from the files above.
GALLERY_LIST="${GALLERY[*]}" BENCH_CMD="bsprt ${BENCH_CMD[*]}" VERTEX_CMD="bsprt ${VERTEX_CMD[*]}" \
  INSIDE_CMD="bsprt ${INSIDE_CMD[*]}" TWINS_CMD="bsprt ${TWINS_CMD[*]}" INTERIOR_CMD="bsprt ${INTERIOR_CMD[*]}" SMALL_CMD="bsprt ${SMALL_CMD[*]}" SCALING_CMD="bsprt ${SCALING_CMD[*]}" ELAPSED=$(($(date +%s) - start)) \
  SCENES="$SCENES" BUILD="$BUILD" GW="$GW" GH="$GH" SPP="$GALLERY_SPP" ERROR_COUNT="$ERROR_COUNT" \
  SCALING_LEVELS="$SCALING_LEVELS" RUNS="$RUNS" \
  scripts/docs_write_performance.sh > docs/performance.md
echo "docs: wrote docs/performance.md, $PERF/, $GAL/ in $(($(date +%s) - start)) s"
