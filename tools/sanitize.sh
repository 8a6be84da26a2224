#!/usr/bin/env bash
# Builds trivox with AddressSanitizer and UndefinedBehaviorSanitizer (clang, -O1 -g) together
# with the libFuzzer harnesses of fuzz/, from the same objects, and runs the tests under them
# (docs/testing.md). Any sanitizer report stops the program, so the test that triggered it fails.
# Usage: tools/sanitize.sh [--build-only]      (build folder: build-asan/; ASAN_BUILD_DIR overrides)
# Run by tools/test.sh after the ordinary tests; tools/fuzz.sh builds through it.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${ASAN_BUILD_DIR:-build-asan}
jobs=$(nproc 2>/dev/null || echo 2)
[ "$jobs" -gt 2 ] || jobs=2

# The benches are not built (speed is not measured here), nor is anything else not run.
modules=(spline geom construct vmodel fillet slice io scene job)
fuzzers=$(sed -n 's/^\([a-z_]*\) .*/fuzz_\1/p' fuzz/seeds.txt)
CC=clang CXX=clang++ cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Debug \
  "-DCMAKE_CXX_FLAGS_DEBUG=-O1 -g" -DTRIVOX_SANITIZE=ON -DTRIVOX_FUZZ=ON >/dev/null
# shellcheck disable=SC2086
cmake --build "$build" -j "$jobs" --target trivox trivox_png "${modules[@]/#/test_}" $fuzzers
[ "${1:-}" = --build-only ] && exit 0

# halt_on_error is implied by -fno-sanitize-recover; leaks are errors too (LeakSanitizer).
# malloc_context_size: every allocation's call stack goes into ASan's stack depot, a hash table
# that slows down as it fills. The surface intersection's recursive subdivision (geom::find_seeds:
# four recursive calls, up to 24 deep) allocates from so many distinct 30-frame stacks that the
# Boolean tests spent 91% of their time there (75 s to over 20 minutes, up to 7.6 GB, per test;
# 1 to 11 s in the ordinary build). Eight frames still name the allocating function and its callers.
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:malloc_context_size=8:check_initialization_order=1:strict_init_order=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1}
# The unit tests, every fuzz target's seeds once, and the end-to-end tests of the readers'
# refusals. The other end-to-end tests slice whole models, 10 to 50 times slower here: the
# ordinary build runs them.
# catch_discover_tests names the unit tests "<module>:<test case>" (its TEST_PREFIX loses the
# trailing space), the others are "fuzz: <target> seeds" and "cli: <script>".
tests="^(($(IFS='|'; echo "${modules[*]}")):|fuzz: |cli: (validate|info_eval|construct)$)"
ctest --test-dir "$build" --output-on-failure -j "$jobs" -R "$tests"
