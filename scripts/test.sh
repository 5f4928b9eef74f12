#!/usr/bin/env bash
# Set up, build and run the test suite (GoogleTest and the Python module's
# pytest suite, python/tests, through ctest).
# Usage: scripts/test.sh [--sanitize | --integration]
#   --sanitize: ASan + UBSan build in build-asan/, without the Python module (an
#     instrumented extension cannot load into python3);
#   --integration: only the heavy checks: the tests labelled `integration` (a
#     real renderer uses atmos's output: Blender, installed here with apt-get when
#     missing) and `fuzz` (the bad-input sweep, the fault and interrupt suites).
# The default run leaves out the labels `slow` and `integration`.
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir=build
if [ "${1:-}" = "--sanitize" ]; then build_dir=build-asan; fi
if [ "${1:-}" = "--integration" ]; then
    scripts/setup.sh
    if ! command -v blender >/dev/null; then
        sudo_cmd=""
        [ "$(id -u)" -ne 0 ] && sudo_cmd=sudo
        $sudo_cmd apt-get update
        $sudo_cmd apt-get install -y --no-install-recommends blender
    fi
    # Reconfigure so that CMake finds Blender and adds the tests.
    cmake "$build_dir" >/dev/null
    ctest --test-dir "$build_dir" --output-on-failure -L 'integration|fuzz'
    exit
fi
scripts/setup.sh "$@"
export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}"
# The fuzz test's queries per model and atmosphere (tests/fuzz_test.cpp): 1e5 by
# default; 2000 under the sanitizers, where each query costs 10-20x.
if [ "${1:-}" = "--sanitize" ]; then export ATMOS_FUZZ_QUERIES="${ATMOS_FUZZ_QUERIES:-2000}"; fi
ctest --test-dir "$build_dir" --output-on-failure -j "$(nproc)" -LE 'slow|integration'
