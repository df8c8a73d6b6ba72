#!/usr/bin/env bash
# CTest "test_names": no Catch2 test case name holds a ';'. catch_discover_tests
# passes names through CMake lists, which split at ';', so such a test was
# registered under a name that matches no test case, and ran nothing while
# CTest reported it passed (five tests did, until 2026-12-05).
# Usage: test_names_test.sh SOURCE_DIR
set -euo pipefail
cd "$1"
bad=$(grep -nE 'TEST_CASE\("[^"]*;' tests/*.cpp fuzz/*.cpp 2>/dev/null || true)
if [ -n "$bad" ]; then
  echo "test case names with ';' (CTest would run nothing for them):"
  echo "$bad"
  exit 1
fi
echo "test_names: no test case name holds ';'"
