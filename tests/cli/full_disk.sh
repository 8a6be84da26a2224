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
echo "full disk: ok"
