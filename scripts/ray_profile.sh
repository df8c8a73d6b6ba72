#!/usr/bin/env bash
# Per-ray instructions, conditional branches and mispredicted branches of each
# accelerator, counted by valgrind's cachegrind (deterministic, unlike
# timings on a shared VM). Each mode traces N rays and then a single ray with
# the same load and build; the difference divided by N-1 is the per-ray cost,
# so mesh loading, tree reading and Embree's build drop out.
# docs/notes/2026-12-01-speed-targets.md quotes this table.
#   scripts/ray_profile.sh                           # bunny, 100000 rays per set
#   scripts/ray_profile.sh path/to/mesh.ply 50000    # another mesh, fewer rays
#   MODES="kd bsp:interleaved bsp-bvh8@16" RAYSETS=random BSPRT_BUILD_DIR=dir BSPRT_SKIP_DEPS=1 scripts/ray_profile.sh
# Run by hand (not in CI): about a minute per mode and ray set on 2 cores.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$(pwd)
SCENE=${1:-$ROOT/../shared/scenes/stanford-bunny.obj}
N=${2:-100000}
BUILD=${BSPRT_BUILD_DIR:-build}
MODES=${MODES:-"kd bsp bsp:sequential bsp-top bsp-bvh8 bvh8-float bvh8 embree"}
RAYSETS=${RAYSETS:-"primary random"}

[ -n "${BSPRT_SKIP_DEPS:-}" ] || scripts/install-deps.sh
if ! command -v valgrind >/dev/null; then
  sudo=""
  if [ "$(id -u)" -ne 0 ]; then sudo="sudo"; fi
  $sudo apt-get update -q
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -q --no-install-recommends valgrind
fi
cmake -S . -B "$BUILD" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$BUILD" --target bsprt -j "$(nproc)"
case "$BUILD" in
  /*) BSPRT="$BUILD/apps/bsprt" ;;
  *) BSPRT="$ROOT/$BUILD/apps/bsprt" ;;
esac

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$BSPRT" build "$SCENE" --accel kd -o "$work/tree.kd" >/dev/null 2>&1
"$BSPRT" build "$SCENE" --accel bsp -o "$work/tree.bsp" >/dev/null 2>&1
for set in $RAYSETS; do
  side=$(awk -v n="$N" 'BEGIN { s = int(sqrt(n) + 0.5); print (s < 1 ? 1 : s) }')
  if [ "$set" = primary ]; then
    "$BSPRT" gen-rays "$SCENE" --kind primary --size "$side" "$side" -o "$work/$set.rays" >/dev/null 2>&1
    "$BSPRT" gen-rays "$SCENE" --kind primary --size 1 1 -o "$work/$set-1.rays" >/dev/null 2>&1
  else
    "$BSPRT" gen-rays "$SCENE" --kind "$set" -n "$N" -o "$work/$set.rays" >/dev/null 2>&1
    "$BSPRT" gen-rays "$SCENE" --kind "$set" -n 1 -o "$work/$set-1.rays" >/dev/null 2>&1
  fi
done

# One cachegrind run: mode (accel[:single-rays][@top-slots]), ray file, output tag.
profile() {
  local mode=${1%%@*} rays=$2 tag=$3 accel=${1%%[:@]*} extra=()
  [[ "$1" == *@* ]] && extra+=(--top-slots "${1#*@}")
  [[ "$mode" == *:* ]] && extra+=(--single-rays "${mode#*:}")
  case "$accel" in
    kd) extra+=(--tree "$work/tree.kd") ;;
    bsp*) extra+=(--tree "$work/tree.bsp") ;;
  esac
  valgrind --tool=cachegrind --cache-sim=no --branch-sim=yes --cachegrind-out-file="$work/$tag.cg" \
    "$BSPRT" trace "$SCENE" "$rays" -o "$work/$tag.hits" --accel "$accel" "${extra[@]}" --threads 1 \
    >"$work/$tag.log" 2>&1
}
# Events of a cachegrind file: Ir Bc Bcm (instructions, cond. branches, their mispredicts).
events() { awk '/^events:/{for(i=2;i<=NF;i++) e[$i]=i} /^summary:/{print $e["Ir"], $e["Bc"], $e["Bcm"]}' "$1"; }
count() { od -An -t u8 -j 8 -N 8 "$1" | tr -d ' '; }  # N of a .rays file (formats.md)

echo "| rays | mode | instructions / ray | cond. branches / ray | mispredicts / ray |"
echo "|---|---|---:|---:|---:|"
for set in $RAYSETS; do
  n=$(count "$work/$set.rays")
  for mode in $MODES; do
    tag="$set-${mode//[:@]/-}"
    profile "$mode" "$work/$set.rays" "$tag" &
    profile "$mode" "$work/$set-1.rays" "$tag-1" &
    wait
    read -r ir bc bcm < <(events "$work/$tag.cg")
    read -r ir1 bc1 bcm1 < <(events "$work/$tag-1.cg")
    awk -v s="$set" -v m="$mode" -v n="$n" -v a="$ir" -v b="$bc" -v c="$bcm" -v a1="$ir1" -v b1="$bc1" -v c1="$bcm1" \
      'BEGIN { d = n - 1; printf "| %s | %s | %.0f | %.1f | %.1f |\n", s, m, (a - a1) / d, (b - b1) / d, (c - c1) / d }'
  done
done
echo
echo "scene $SCENE, $N rays per set, --threads 1, $(valgrind --version), $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')"
