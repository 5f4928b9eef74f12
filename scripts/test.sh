#!/usr/bin/env bash
# Set up, build and run the test suite (GoogleTest and the Python module's
# pytest suite, python/tests, through ctest).
# Usage: scripts/test.sh [--sanitize]   (--sanitize: ASan + UBSan build in build-asan/,
# without the Python module: an instrumented extension cannot load into python3)
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir=build
if [ "${1:-}" = "--sanitize" ]; then build_dir=build-asan; fi
scripts/setup.sh "$@"
export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}"
ctest --test-dir "$build_dir" --output-on-failure -j "$(nproc)" -LE slow
