#!/usr/bin/env bash
# CTest "public_headers": every header of include/bsprt/ compiles on its own
# with only bsprt's include folders, and no dependency's header is reachable
# from it: every bsprt header it opens, transitively (the preprocessor's own
# list), includes only standard library headers (<name>, no folder) and other
# bsprt/ headers. (What the standard library itself opens is its business:
# libstdc++'s parallel algorithms may open <tbb/tbb.h> under clang.)
# Usage: public_headers_test.sh SOURCE_DIR BUILD_DIR CXX
set -euo pipefail
src=$1 build=$2 cxx=$3
fail=0
for h in "$src"/include/bsprt/*.h; do
  name=$(basename "$h")
  tu="#include \"bsprt/$name\""
  if ! deps=$(echo "$tu" | "$cxx" -std=c++20 -M -I "$src/include" -I "$build/include" -x c++ -); then
    echo "FAIL: $name does not compile alone"; fail=1; continue
  fi
  own=$(echo "$deps" | tr ' \\' '\n\n' | grep -E "^($src/include|$build/include)/bsprt/" | sort -u)
  for f in $own; do
    while IFS= read -r inc; do
      case "$inc" in
        '<'*/*'>') echo "FAIL: $name reaches $(basename "$f"), which includes $inc"; fail=1 ;;
        '"bsprt/'*) ;;
        '"'*) echo "FAIL: $name reaches $(basename "$f"), which includes $inc (not a bsprt/ header)"; fail=1 ;;
      esac
    done < <(sed -n 's/^[[:space:]]*#[[:space:]]*include[[:space:]]*\([<"][^>"]*[>"]\).*/\1/p' "$f")
  done
  echo "$tu" | "$cxx" -std=c++20 -fsyntax-only -Wall -Wextra -Werror -I "$src/include" -I "$build/include" -x c++ - || fail=1
done
[ $fail -eq 0 ] && echo "public headers: $(ls "$src"/include/bsprt/*.h | wc -l) headers, self-contained, only standard and bsprt/ includes"
exit $fail
