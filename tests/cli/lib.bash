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
