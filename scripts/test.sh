#!/usr/bin/env bash
# Set up, build and run the test suite (GoogleTest and the Python module's
# pytest suite, python/tests, through ctest).
# Usage: scripts/test.sh [--sanitize | --integration]   (--sanitize: ASan + UBSan build in
# build-asan/, without the Python module: an instrumented extension cannot load into
# python3; --integration: also the fuzz and fault suite, `ctest -L fuzz`, issue 38 item 5)
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir=build
integration=0
if [ "${1:-}" = "--sanitize" ]; then build_dir=build-asan; fi
if [ "${1:-}" = "--integration" ]; then integration=1; shift; fi
scripts/setup.sh "$@"
export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}"
# The fuzz test's queries per model and atmosphere (tests/fuzz_test.cpp): 1e5 by
# default; 2000 under the sanitizers, where each query costs 10-20x.
if [ "${1:-}" = "--sanitize" ]; then export ATMOS_FUZZ_QUERIES="${ATMOS_FUZZ_QUERIES:-2000}"; fi
ctest --test-dir "$build_dir" --output-on-failure -j "$(nproc)" -LE slow
if [ "$integration" = 1 ]; then
  ctest --test-dir "$build_dir" --output-on-failure -L fuzz
fi
