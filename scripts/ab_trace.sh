#!/usr/bin/env bash
# A/B timing of `bsprt trace` on a noisy machine: every variant runs once per
# round, in the same order, for ROUNDS rounds; each run takes the best of
# `--passes 3` with one thread, and the table keeps each variant's fastest
# round. Variants are label:binary:accel, so two builds of bsprt (an old one
# copied aside and the current one) or two modes of one build alternate in
# one sitting: this VM's speed drifts by up to 1.5x between sittings, so
# only times taken this way are compared in the lab notes. It also checks
# that variants of one accelerator wrote byte-identical hits, and exits 1
# (after the table) when they did not.
#   scripts/ab_trace.sh SCENE RAYS TREE ROUNDS label:BIN:accel ...
#   scripts/ab_trace.sh sponza.obj cam.rays sponza.bsp 5 old:/tmp/bsprt.old:bsp new:build/apps/bsprt:bsp
# TREE is passed to bsp* accelerators; KD_TREE=file passes one to kd*.
# EXTRA="--packets 16" adds options to every run (the CLI refuses --packets for single-ray-only
# accelerators: bvh8, bsp-top, bsp-bvh8, exact). Not run in CI (timing).
set -euo pipefail
if [ $# -lt 5 ]; then
  sed -n '2,14p' "$0" | sed 's/^# \{0,1\}//' >&2
  exit 2
fi
scene=$1 rays=$2 tree=$3 rounds=$4
shift 4
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
declare -A best
labels=()
for spec in "$@"; do
  IFS=: read -r label bin accel <<<"$spec"
  [ -x "$bin" ] || { echo "ab_trace.sh: $bin is not an executable (from $spec)" >&2; exit 2; }
  labels+=("$label")
done
for ((r = 1; r <= rounds; ++r)); do
  for spec in "$@"; do
    IFS=: read -r label bin accel <<<"$spec"
    args=()
    case $accel in
      bsp*) args=(--tree "$tree") ;;
      kd*) [ -n "${KD_TREE:-}" ] && args=(--tree "$KD_TREE") ;;
    esac
    # shellcheck disable=SC2086  # EXTRA is split into options on purpose
    log=$("$bin" trace "$scene" "$rays" "${args[@]}" --accel "$accel" --threads 1 --passes 3 ${EXTRA:-} \
      -o "$out/$label.hits" 2>&1) || { echo "$log" >&2; exit 1; }
    t=$(grep -o 'trace [0-9.]* s' <<<"$log" | awk '{print $2}')
    [ -n "$t" ] || { echo "ab_trace.sh: no time in the output of $spec:" >&2; echo "$log" >&2; exit 1; }
    if [ -z "${best[$label]:-}" ] || awk -v a="$t" -v b="${best[$label]}" 'BEGIN{exit !(a < b)}'; then
      best[$label]=$t
    fi
  done
done
printf '%-16s %s\n' variant "best of $rounds rounds (s)"
for label in "${labels[@]}"; do printf '%-16s %s\n' "$label" "${best[$label]}"; done
# Same accelerator, different binaries: the hits must not differ.
declare -A first_of
status=0
for spec in "$@"; do
  IFS=: read -r label bin accel <<<"$spec"
  if [ -n "${first_of[$accel]:-}" ]; then
    if ! cmp -s "$out/${first_of[$accel]}.hits" "$out/$label.hits"; then
      echo "ab_trace.sh: $label and ${first_of[$accel]} ($accel) wrote different hits" >&2
      status=1
    fi
  else
    first_of[$accel]=$label
  fi
done
exit $status
