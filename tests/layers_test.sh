#!/usr/bin/env bash
# CTest "include_layers": no include runs up a layer. The folders, bottom up
# (each library may include its own folder and the ones below it):
#   0 include/bsprt, geometry/core   public types, triangle soup      bsprt::core
#   1 traverse (kd/, bsp/, bvh/, simd/) float traversal, no CGAL     bsprt::traverse
#   2 traverse/embree                Embree behind Accelerator        bsprt::embree
#   3 robust                         exact predicates (CGAL)          bsprt::robust
#   4 geometry/io, geometry/scenes   files, made scenes and rays      bsprt::geometry
#   5 builder (kd/, bsp/)            builds, tree files, accel table  bsprt::builder
#   6 verify                         the independent checker          bsprt::verify
#   7 apps                           renderer, bench, the CLI
#   8 api                            the public library               bsprt::bsprt
#   9 python                         the Python module
# tests/, fuzz/, bench/ and examples/ may include anything.
# Usage: layers_test.sh SOURCE_DIR
set -euo pipefail
cd "$1"
layer_of() {  # folder of a path (longest prefix first) -> layer number
  case "$1" in
    include/bsprt/*|bsprt/*|geometry/core/*) echo 0 ;;
    traverse/embree/*) echo 2 ;;
    traverse/*) echo 1 ;;
    robust/*) echo 3 ;;
    geometry/io/*|geometry/scenes/*) echo 4 ;;
    builder/*) echo 5 ;;
    verify/*) echo 6 ;;
    apps/*) echo 7 ;;
    api/*) echo 8 ;;
    python/*) echo 9 ;;
    *) echo "" ;;
  esac
}
fail=0 checked=0
while IFS= read -r f; do
  own=$(layer_of "$f")
  [ -z "$own" ] && { echo "FAIL: $f is in no layer"; fail=1; continue; }
  while IFS= read -r inc; do
    [ -z "$inc" ] && continue
    l=$(layer_of "$inc")
    checked=$((checked + 1))
    if [ -z "$l" ]; then echo "FAIL: $f includes \"$inc\", which is in no layer"; fail=1
    elif [ "$l" -gt "$own" ]; then echo "FAIL: $f (layer $own) includes \"$inc\" (layer $l)"; fail=1; fi
  done < <(sed -n 's/^[[:space:]]*#[[:space:]]*include[[:space:]]*"\([^"]*\)".*/\1/p' "$f")
done < <(git ls-files --cached --others --exclude-standard 'include/*' 'geometry/*' 'traverse/*' 'robust/*' 'builder/*' 'verify/*' 'apps/*' 'api/*' 'python/*' \
         | grep -E '\.(h|cpp|inl)$')
[ $fail -eq 0 ] && echo "include_layers: $checked includes checked, none runs up a layer"
exit $fail
