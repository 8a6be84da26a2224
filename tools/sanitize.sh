#!/usr/bin/env bash
# Builds trivox with AddressSanitizer and UndefinedBehaviorSanitizer (clang, -O1) together with
# the libFuzzer harnesses of fuzz/, from the same objects, and runs the tests under them
# (docs/testing.md). Any sanitizer report stops the program, so the test that triggered it fails.
# Usage: tools/sanitize.sh [--unit] [--build-only]   (build folder: build-asan/; ASAN_BUILD_DIR
#        overrides)
#   (none)        the unit tests, every fuzz target's seeds, and the end-to-end tests of the
#                 readers' refusals with the sanitized trivox
#   --unit        the unit tests and the seeds only: the command line is not built (what
#                 tools/test.sh runs in CI, where time is short)
#   --build-only  build what the run would need, run nothing
#   --fuzz        (with --build-only) the fuzz harnesses only: tools/fuzz.sh builds through this
set -euo pipefail
cd "$(dirname "$0")/.."
build=${ASAN_BUILD_DIR:-build-asan}
jobs=$(nproc 2>/dev/null || echo 2)
[ "$jobs" -gt 2 ] || jobs=2
unit=0 build_only=0 fuzz_only=0
for arg in "$@"; do
  case $arg in
    --unit) unit=1 ;;
    --build-only) build_only=1 ;;
    --fuzz) fuzz_only=1 ;;
    *) echo "sanitize.sh: unknown option '$arg'; expected --unit, --build-only or --fuzz" >&2; exit 2 ;;
  esac
done

# The benches are not built (speed is not measured here), nor is anything else not run.
modules=(spline geom construct vmodel fillet slice io scene job)
mapfile -t fuzzers < <(sed -n 's/^\([a-z_]*\) .*/fuzz_\1/p' fuzz/seeds.txt)
targets=("${fuzzers[@]}")
[ $fuzz_only = 1 ] || targets+=(trivox_png "${modules[@]/#/test_}")
[ $fuzz_only = 1 ] || [ $unit = 1 ] || targets+=(trivox)
# -gline-tables-only: reports need files and lines, not variables; full -g took 5 to 8% more
# compile time in the files measured.
CC=clang CXX=clang++ cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Debug \
  "-DCMAKE_CXX_FLAGS_DEBUG=-O1 -gline-tables-only" -DTRIVOX_SANITIZE=ON -DTRIVOX_FUZZ=ON >/dev/null
cmake --build "$build" -j "$jobs" --target "${targets[@]}"
[ $build_only = 1 ] && exit 0

# halt_on_error is implied by -fno-sanitize-recover; leaks are errors too (LeakSanitizer).
# malloc_context_size: every allocation's call stack goes into ASan's stack depot, a hash table
# that slows down as it fills. The surface intersection's recursive subdivision (geom::find_seeds:
# four recursive calls, up to 24 deep) allocates from so many distinct 30-frame stacks that the
# Boolean tests spent 91% of their time there (75 s to over 20 minutes, up to 7.6 GB, per test;
# 1 to 11 s in the ordinary build). Eight frames still name the allocating function and its callers.
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:malloc_context_size=8:check_initialization_order=1:strict_init_order=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1}
# catch_discover_tests names the unit tests "<module>:<test case>" (its TEST_PREFIX loses the
# trailing space), the others are "fuzz: <target> seeds" and "cli: <script>". The end-to-end
# tests kept are those of the readers' refusals; the others slice whole models, 10 to 50 times
# slower here: the ordinary build runs them.
tests="^($(IFS='|'; echo "${modules[*]}")):|^fuzz: "
[ $unit = 1 ] || tests+="|^cli: (validate|info_eval|construct|fuzz_regressions)$"
ctest --test-dir "$build" --output-on-failure -j "$jobs" -R "$tests"
