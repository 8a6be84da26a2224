#!/usr/bin/env bash
# End-to-end: `trivox locate` on shipped models, JSON read back by Python's json.
# Truths: the demo model's block is the trilinear box [0,40] x [0,20] x [0,10] (u, v, w along x,
# y, z), so (10, 10, 5) lies in it at (0.25, 0.5, 0.5); the Fichera corner is [-1,1]^3 without
# the octant x, y < 0 < z; a point's properties equal `trivox eval` at the located (u,v,w).
set -euo pipefail
source tests/cli/lib.bash "$@"

"$trivox" locate models/graded_block.json --xyz 10,10,5 --json > "$tmp/in.json"
"$py" - "$tmp/in.json" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
assert r["inside"] is True and r["cell"] == "block", r
assert all(abs(a - b) < 1e-6 for a, b in zip(r["uvw"], [0.25, 0.5, 0.5])), r["uvw"]
assert all(abs(a - b) < 1e-6 for a, b in zip(r["point"], [10, 10, 5])), r["point"]
assert list(r["properties"]) == ["r", "g", "b"]
PY

# The properties equal `trivox eval` at the located (u,v,w), in the arch too (a quadratic cell
# whose top at x = 20 spans 25 <= z <= 29).
for xyz in 10,10,5 20,10,27 3.5,7.25,16; do
  "$trivox" locate models/graded_block.json --xyz "$xyz" --json > "$tmp/loc.json"
  read -r cell uvw < <("$py" -c 'import json,sys; r=json.load(open(sys.argv[1])); assert r["inside"], r; print(r["cell"], ",".join(repr(x) for x in r["uvw"]))' "$tmp/loc.json")
  "$trivox" eval models/graded_block.json --cell "$cell" --uvw "$uvw" --json > "$tmp/eval.json"
  "$py" - "$tmp/loc.json" "$tmp/eval.json" "$xyz" <<'PY'
import json, sys
loc, ev = json.load(open(sys.argv[1])), json.load(open(sys.argv[2]))
q = [float(x) for x in sys.argv[3].split(",")]
assert loc["properties"] == ev["properties"], (loc["properties"], ev["properties"])
assert loc["point"] == ev["point"], (loc["point"], ev["point"])
assert sum((a - b) ** 2 for a, b in zip(loc["point"], q)) ** 0.5 < 1e-6, (loc["point"], q)
PY
done

# Outside: every field but "inside" is null.
"$trivox" locate models/graded_block.json --xyz 100,10,5 --json > "$tmp/out.json"
"$py" - "$tmp/out.json" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
assert r["inside"] is False and r["cell"] is None and r["uvw"] is None, r
assert r["point"] is None and r["properties"] is None, r
PY

# The Fichera corner: seven octants inside, one outside; G+Smo files work as well.
"$py" - "$trivox" <<'PY'
import json, subprocess, sys
outside = 0
for o in range(8):
    p = [0.5 if o & 1 else -0.5, 0.5 if o & 2 else -0.5, 0.5 if o & 4 else -0.5]
    r = json.loads(subprocess.run([sys.argv[1], "locate", "models/gismo/fichera.xml", "--xyz", ",".join(map(str, p)), "--json"],
                                  check=True, capture_output=True, text=True).stdout)
    if not r["inside"]:
        outside += 1
        assert p[0] < 0 and p[1] < 0 and p[2] > 0, p
    else:
        assert all(abs(a - b) < 1e-6 for a, b in zip(r["point"], p)), (r, p)
assert outside == 1
PY

# Human output.
"$trivox" locate models/graded_block.json --xyz 10,10,5 | grep -q "inside cell block at (u, v, w) = (0.25, 0.5, 0.5)"
"$trivox" locate models/graded_block.json --xyz 100,10,5 | grep -q "outside every cell"

# Bad input: exit 2 and a message naming what was expected; nothing on stdout.
expect_fail "expected 3 comma-separated numbers" "$trivox" locate models/graded_block.json --xyz 1,2
expect_fail "not a finite number" "$trivox" locate models/graded_block.json --xyz 1,inf,2
expect_fail "not a finite number" "$trivox" locate models/graded_block.json --xyz 1,x,2
expect_fail "no-such.json" "$trivox" locate no-such.json --xyz 1,2,3
expect_fail "--tolerance" "$trivox" locate models/graded_block.json --xyz 1,2,3 --tolerance 0
expect_fail "has no cells" "$trivox" locate models/gismo/teapot.xml --xyz 0,0,0
expect_fail "" "$trivox" locate models/graded_block.json
echo "cli locate: ok"
