# Shared by the end-to-end scripts (sourced; not a test itself): `source tests/cli/lib.bash "$@"`
# right after `set -euo pipefail` sets $trivox (the binary under test, the script's first
# argument), $py (the system Python, with numpy) and $tmp (a folder removed on exit).
trivox=$1
py=/usr/bin/python3
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# expect_fail PATTERN command...: the command exits 2, says PATTERN on stderr, prints nothing on
# stdout.
expect_fail() {
  local pattern=$1; shift
  set +e
  "$@" > "$tmp/out" 2> "$tmp/err"
  local rc=$?
  set -e
  if [ $rc -ne 2 ]; then echo "expected exit 2, got $rc: $*"; cat "$tmp/err"; exit 1; fi
  if ! grep -q -- "$pattern" "$tmp/err"; then echo "message lacks '$pattern': $*"; cat "$tmp/err"; exit 1; fi
  if [ -s "$tmp/out" ]; then echo "unexpected stdout: $*"; exit 1; fi
}

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
