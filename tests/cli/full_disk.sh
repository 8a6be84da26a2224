#!/usr/bin/env bash
# A write that fails for want of room is a failure on valid input: exit 1, not 2 (bad input),
# and a message that says what is needed. The file-size limit (ulimit -f, with SIGXFSZ ignored so
# that write() returns EFBIG) stands in for a full disk: no privileges or mounts needed.
set -euo pipefail
source tests/cli/lib.bash "$@"

set +e
(trap '' XFSZ; ulimit -f 4; "$trivox" slice models/graded_block.json -o "$tmp/job" --dpi 300,300 --layer 0.1 \
   --progress never > "$tmp/out" 2> "$tmp/err")
rc=$?
set -e
[ $rc -eq 1 ] || { echo "expected exit 1, got $rc"; cat "$tmp/err"; exit 1; }
grep -q "slice_0.png: cannot write: File too large; expected room on the disk" "$tmp/err" || { cat "$tmp/err"; exit 1; }
# An unwritable folder is the user's to change: exit 2.
mkdir "$tmp/ro" && chmod 500 "$tmp/ro"
if [ "$(id -u)" -ne 0 ]; then   # root writes anywhere
  expect_fail "expected a writable" "$trivox" slice models/graded_block.json -o "$tmp/ro/job" --dpi 100,100 --layer 1
fi
# A job that stops on a full disk records the layers it finished, and --resume keeps them: the
# twisted column's slices grow from 2.6 kB at the bottom, so a limit of 5 KiB (5120 bytes) lets
# the first few through and stops a later one (the manifest, about 3 kB then, still fits). The
# layers it must keep are those of an uninterrupted run's leading slices of at most 5120 bytes.
col=(models/twisted_column.json --dpi 100,100 --layer 0.5 --progress never)
"$trivox" slice "${col[@]}" -o "$tmp/straight" > /dev/null
fit=$(cd "$tmp/straight" && n=0; while [ -e "slice_$n.png" ] && [ "$(stat -c %s "slice_$n.png")" -le 5120 ]; do n=$((n + 1)); done; echo $n)
[ "$fit" -gt 0 ] && [ -e "$tmp/straight/slice_$fit.png" ] || { echo "the limit should stop a later layer (fit: $fit)"; exit 1; }
set +e
(trap '' XFSZ; ulimit -f 5; "$trivox" slice "${col[@]}" -o "$tmp/col" > "$tmp/out" 2> "$tmp/err")
rc=$?
set -e
[ $rc -eq 1 ] || { echo "expected exit 1, got $rc"; cat "$tmp/err"; exit 1; }
grep -q "slice_$fit.png: cannot write: File too large" "$tmp/err" || { cat "$tmp/err"; exit 1; }
"$py" - "$tmp/col/manifest.json" "$fit" <<'PY'
import sys, json
m = json.load(open(sys.argv[1]))
assert m["complete"] is False
assert [l["index"] for l in m["layers"]] == list(range(int(sys.argv[2]))), [l["index"] for l in m["layers"]]
PY
"$trivox" slice "${col[@]}" -o "$tmp/col" --resume > "$tmp/out"
grep -q "resumed: $fit layers kept" "$tmp/out" || { cat "$tmp/out"; exit 1; }
[ "$(ls "$tmp/straight" | sort)" = "$(ls "$tmp/col" | sort)" ]
for f in "$tmp/straight"/*; do cmp "$f" "$tmp/col/$(basename "$f")"; done
echo "full disk: ok"
