#!/usr/bin/env bash
# Fuzzes trivox's readers with libFuzzer under AddressSanitizer and UndefinedBehaviorSanitizer
# (docs/testing.md): each target of fuzz/seeds.txt for SECONDS, starting from its seeds.
# Usage: tools/fuzz.sh [SECONDS [TARGET...]]   (default 60 s each, every target; ASAN_BUILD_DIR
#        as tools/sanitize.sh, which builds the harnesses; FUZZ_JOBS targets at a time, default 2)
# What a fuzzer learns stays in $build/fuzz/corpus/<target>/ and seeds the next run; a finding
# (crash, sanitizer report, an exception other than trivox::Error, a timeout of 10 s for one
# input or more than 2 GB) is written to $build/fuzz/findings/ and makes the script exit 1.
# A finding becomes a regression test: its input in tests/data/fuzz/ (tests/cli/fuzz_regressions.sh
# loads each file there), and in fuzz/corpus/<target>/ so the seed test replays it.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
shift $(($# > 0 ? 1 : 0))
build=${ASAN_BUILD_DIR:-build-asan}
targets=("$@")
[ ${#targets[@]} -gt 0 ] || mapfile -t targets < <(sed -n 's/^\([a-z_]*\) .*/\1/p' fuzz/seeds.txt)
for t in "${targets[@]}"; do
  grep -q "^$t " fuzz/seeds.txt || { echo "fuzz: $t: unknown target; expected one of fuzz/seeds.txt" >&2; exit 2; }
done

tools/sanitize.sh --build-only --fuzz
root=$PWD
build=$(cd "$build" && pwd)
# malloc_context_size as in tools/sanitize.sh: the stack depot grows with every new allocation stack.
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:malloc_context_size=8}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1}
mkdir -p "$build/fuzz/findings"
# The scene reader opens G+Smo files a scene names, relative to the working folder: an empty one.
mkdir -p "$build/fuzz/cwd"

fuzz_one() {
  local t=$1 seeds=()
  read -r -a seeds <<< "$(sed -n "s/^$t  *//p" "$root/fuzz/seeds.txt")"
  mkdir -p "$build/fuzz/corpus/$t"
  local log="$build/fuzz/$t.log" rc=0
  (cd "$build/fuzz/cwd" && exec "$build/fuzz/fuzz_$t" -max_total_time="$seconds" -timeout=10 \
     -rss_limit_mb=2048 -max_len=65536 -print_final_stats=1 \
     -artifact_prefix="$build/fuzz/findings/$t-" "$build/fuzz/corpus/$t" "${seeds[@]/#/$root/}") \
    > "$log" 2>&1 || rc=$?
  local runs
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log")
  if [ $rc -ne 0 ]; then
    echo "fuzz: $t: FINDING after ${runs:-?} inputs; $log:"
    grep -E '^(==[0-9]+==ERROR|SUMMARY|fuzz:|.*runtime error|artifact_prefix|Test unit written)' "$log" | head -20
    return 1
  fi
  echo "fuzz: $t: ${runs:-?} inputs in ${seconds} s, no finding; corpus $(ls "$build/fuzz/corpus/$t" | wc -l) files"
}
export -f fuzz_one
export build seconds root

failed=0
printf '%s\n' "${targets[@]}" | xargs -P "${FUZZ_JOBS:-2}" -I{} bash -c 'fuzz_one {}' || failed=1
exit $failed
