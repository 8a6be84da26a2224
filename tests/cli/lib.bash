# Shared by the end-to-end scripts (sourced; not a test itself): `source tests/cli/lib.bash "$@"`
# right after `set -euo pipefail` sets $trivox (the binary under test, the script's first
# argument), $py (the system Python, with numpy) and $tmp (a folder removed on exit).
trivox=$1
py=/usr/bin/python3
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# expect_exit RC PATTERN FILE command...: the command exits RC and says PATTERN on stderr; with
# RC 2 (bad input) it prints nothing on stdout; FILE (unless "-") does not exist afterwards.
expect_exit() {
  local want=$1 pattern=$2 file=$3; shift 3
  set +e
  "$@" > "$tmp/out" 2> "$tmp/err"
  local rc=$?
  set -e
  if [ $rc -ne "$want" ]; then echo "expected exit $want, got $rc: $*"; cat "$tmp/err"; exit 1; fi
  if ! grep -q -- "$pattern" "$tmp/err"; then echo "message lacks '$pattern': $*"; cat "$tmp/err"; exit 1; fi
  if [ "$want" -eq 2 ] && [ -s "$tmp/out" ]; then echo "unexpected stdout: $*"; exit 1; fi
  if [ "$file" != - ] && [ -e "$file" ]; then echo "$file was written after the failure: $*"; exit 1; fi
}
# expect_fail PATTERN command...: bad input (exit 2), nothing on stdout.
expect_fail() { local pattern=$1; shift; expect_exit 2 "$pattern" - "$@"; }
# expect_failed PATTERN OUTPUT command...: the operation failed on valid input (exit 1), OUTPUT
# not written.
expect_failed() { local pattern=$1 output=$2; shift 2; expect_exit 1 "$pattern" "$output" "$@"; }

# corner_scene FILE OPERATIONS: the floor-and-wall corner of the fillet scripts (floor
# [0,4]x[0,4]x[-1,0] red, wall [1,2]x[-0.5,4.5]x[-0.5,3] blue) with OPERATIONS (JSON array
# elements, may be empty). fillet_op FIELDS: a fillet between the floor's top and the wall's
# x = 2 face with the extra FIELDS.
corner_scene() {
  cat > "$1" <<EOF
{ "trivox": 1, "units": "mm", "properties": ["r", "g", "b"],
  "cells": [
    {"name": "floor", "primitive": {"type": "box", "min": [0, 0, -1], "max": [4, 4, 0]}, "field": {"constant": [1, 0, 0]}},
    {"name": "wall", "primitive": {"type": "box", "min": [1, -0.5, -0.5], "max": [2, 4.5, 3]}, "field": {"constant": [0, 0, 1]}}
  ],
  "operations": [$2] }
EOF
}
fillet_op() { echo '{"op": "fillet", "between": [{"cell": "floor", "face": "w1"}, {"cell": "wall", "face": "u1"}], '"$1"'}'; }
