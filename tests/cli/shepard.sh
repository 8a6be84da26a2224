#!/usr/bin/env bash
# End-to-end: fillets with the Shepard blend (Masalha et al. 2021, Sec. 7.2; fillet/shepard.hpp). A
# floor z <= 0 (red) and a wall x <= 2 (blue), filleted with "blend": "shepard", "power": 3: the
# sub-regions are the planar strips S^_1 = {z = 0, 2 <= x <= 3} and S^_2 = {x = 2, 0 <= z <= 0.5},
# so inside the fillet d_1 = z, d_2 = x - 2 and f is analytic (numpy, independently):
# alpha_floor = z^-q / (z^-q + (x - 2)^-q), rgb = (alpha_floor, 0, 1 - alpha_floor).
# `trivox locate --blend shepard` gives f to 1e-9; the encoded control points (the default) stay
# within the fit's error of it; the model file carries the Shepard data; `trivox slice
# --blend shepard` writes the same bytes with 1 and 2 threads, and differs from the encoded
# slice only where the fit's error changes a voxel. Bad powers and blends exit 2.
set -euo pipefail
source tests/cli/lib.bash "$@"

scene() {  # scene EXTRA-FIELDS
  cat > "$tmp/corner.json" <<EOF
{ "trivox": 1, "units": "mm", "properties": ["r", "g", "b"],
  "cells": [
    {"name": "floor", "primitive": {"type": "box", "min": [0, 0, -1], "max": [4, 4, 0]}, "field": {"constant": [1, 0, 0]}},
    {"name": "wall", "primitive": {"type": "box", "min": [1, -0.5, -0.5], "max": [2, 4.5, 3]}, "field": {"constant": [0, 0, 1]}}
  ],
  "operations": [{"op": "fillet", "between": [{"cell": "floor", "face": "w1"}, {"cell": "wall", "face": "u1"}],
                  "distance": [1.0, 0.5], "tau": 1.2 $1}] }
EOF
}

scene ', "blend": "shepard", "power": 3'
"$trivox" build "$tmp/corner.json" -o "$tmp/model.json" --json > "$tmp/build.json"
"$py" - "$tmp/model.json" <<'PY'
import sys, json
m = json.load(open(sys.argv[1]))
cells = {c["name"]: c for c in m["cells"]}
for n in ("fillet.1a", "fillet.1b"):
    s = cells[n]["shepard"]
    assert s["power"] == 3 and len(s["surfaces"]) == 2, s.keys()
assert cells["fillet.1a"]["shepard"] == cells["fillet.1b"]["shepard"]
assert "shepard" not in cells["floor.box"] if "floor.box" in cells else True
PY

# Points inside the fillet (x > 2, z > 0, near the corner), exact and encoded.
points="2.2,2,0.1 2.05,1,0.2 2.3,3.5,0.05 2.1,0.5,0.1 2.02,2.5,0.02 2.15,1.7,0.08 2.12,2.2,0.03"
: > "$tmp/located"
for p in $points; do
  "$trivox" locate "$tmp/model.json" --xyz "$p" --blend shepard --json > "$tmp/exact.json"
  "$trivox" locate "$tmp/model.json" --xyz "$p" --json > "$tmp/encoded.json"
  echo "$p $(tr -d '\n ' < "$tmp/exact.json") $(tr -d '\n ' < "$tmp/encoded.json")" >> "$tmp/located"
done
"$py" - "$tmp/located" <<'PY'
import sys, json
import numpy as np
q = 3
worst_exact = worst_encoded = 0.0
for line in open(sys.argv[1]):
    p, exact, encoded = line.split(" ", 2)
    x, y, z = map(float, p.split(","))
    e, c = json.loads(exact), json.loads(encoded)
    assert e["inside"] and e["cell"].startswith("fillet."), (p, e)
    assert c["cell"] == e["cell"], (p, c)
    a = z ** -q / (z ** -q + (x - 2) ** -q)
    want = np.array([a, 0.0, 1.0 - a])
    got = np.array([e["properties"][k] for k in "rgb"])
    enc = np.array([c["properties"][k] for k in "rgb"])
    assert abs(e["shepard"]["distance"][0] - z) < 1e-9 and abs(e["shepard"]["distance"][1] - (x - 2)) < 1e-9, (p, e["shepard"])
    assert abs(sum(e["shepard"]["alpha"]) - 1) < 1e-15
    worst_exact = max(worst_exact, np.abs(got - want).max())
    worst_encoded = max(worst_encoded, np.abs(enc - want).max())
    print(p, "exact", got.round(4), "encoded", enc.round(4))
assert worst_exact < 1e-9, worst_exact
assert worst_encoded < 0.05, worst_encoded
print(f"shepard: exact f within {worst_exact:.2g} of the formula, encoded within {worst_encoded:.2g}")
PY

# On the faces: f is the face's colour (feature preservation), exactly where a distance is 0.
"$trivox" locate "$tmp/model.json" --xyz 2.5,2,0 --blend shepard --json > "$tmp/onfloor.json"
"$py" -c "
import json, sys
j = json.load(open('$tmp/onfloor.json'))
assert j['inside'] and j['properties'] == {'r': 1.0, 'g': 0.0, 'b': 0.0}, j
"

# The slice: exact Shepard per voxel, the same bytes for 1 and 2 threads.
for t in 1 2; do
  "$trivox" slice "$tmp/model.json" -o "$tmp/s$t" --dpi 300,300 --layer 0.1 --blend shepard --threads $t --progress never --json > "$tmp/slice$t.json"
done
"$trivox" slice "$tmp/model.json" -o "$tmp/enc" --dpi 300,300 --layer 0.1 --threads 2 --progress never --json > "$tmp/slice_enc.json"
"$py" - "$tmp/s1/manifest.json" "$tmp/s2/manifest.json" "$tmp/enc/manifest.json" <<'PY'
import sys, json
a, b, c = (json.load(open(f)) for f in sys.argv[1:4])
la = [l["sha256"] for l in a["layers"]]
lb = [l["sha256"] for l in b["layers"]]
assert la == lb, "shepard slices differ between 1 and 2 threads"
assert a["options"].get("blend") == "shepard", a["options"]
assert "blend" not in c["options"], c["options"]
PY

# Bad input.
scene ', "blend": "shepard", "power": 0'
expect_fail "/operations/0/power" "$trivox" build "$tmp/corner.json" -o "$tmp/bad.json"
expect_fail "1..16" "$trivox" build "$tmp/corner.json" -o "$tmp/bad.json"
scene ', "blend": "parametric", "power": 2'
expect_fail "only with the Shepard blend" "$trivox" build "$tmp/corner.json" -o "$tmp/bad.json"
scene ', "blend": "idw"'
expect_fail 'expected "parametric" or "shepard"' "$trivox" build "$tmp/corner.json" -o "$tmp/bad.json"
expect_fail "expected encoded or shepard" "$trivox" slice "$tmp/model.json" -o "$tmp/bad" --blend exact
expect_fail "expected encoded or shepard" "$trivox" locate "$tmp/model.json" --xyz 2.2,2,0.1 --blend exact
echo "shepard: ok"
