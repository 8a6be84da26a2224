#!/usr/bin/env bash
# End-to-end: the scene operation "fillet" (Masalha et al. 2021, Alg. 2, Sec. 7.1; Flends Sec. II)
# built by `trivox build` and seen by `trivox locate`. Truths: between a floor z <= 0 and a wall x
# <= 2 (boxes, faces chosen), the dip-0 flend is the chamfer, a prism of volume d1 d2 / 2 times the
# length 4; the Hermite fillet's volume is 4 times the area its section (a cubic with known
# control points) cuts from the corner, by Green's theorem in numpy; both meet the faces with no
# gap, G1 below 1e-6 rad, det J > 0 inside, and carry each box's colour on its face. Points just
# inside and outside the chamfer plane are in and out of the fillet, and the printed volume
# counts the chamfer (32.5 mm^3 within 0.5 percent). The shipped models build.
# Bad fillets exit 2 naming the operation and what is wrong; a fillet whose det J changes sign
# exits 1 and is not written. A bridge between disjoint boxes has the analytic volume.
set -euo pipefail
source tests/cli/lib.bash "$@"

corner() { corner_scene "$tmp/corner.json" "$(fillet_op "$1")"; }  # corner FILLET-FIELDS

check() {  # check BUILD-JSON KIND: the quality report and the fillet's volume
  "$py" - "$1" "$2" <<'PY'
import sys, json
import numpy as np
sys.path.insert(0, "tests/cli")
from fillet_math import hermite_area
r = json.load(open(sys.argv[1]))
kind = sys.argv[2]
d1, d2, length = 1.0, 0.5, 4.0
(f,) = r["fillets"]
assert f["cells"] == ["fillet.1a", "fillet.1b"], f["cells"]
assert f["between"] == [{"cell": "floor", "face": "w1"}, {"cell": "wall", "face": "u1"}], f["between"]
assert max(f["gap"]) < 1e-12, f["gap"]
assert max(f["property_jump"]) < 1e-12, f["property_jump"]
assert f["jacobian"] == "positive" and f["min_jacobian"] > 0, f
assert f["composed"] == [True, True], f["composed"]
vol = sum(c["volume"] for c in r["cells"] if c["name"].startswith("fillet."))
if kind == "chamfer":
    exact = d1 * d2 / 2 * length
else:
    assert max(f["g1_angle"]) < 1e-6, f["g1_angle"]
    exact = hermite_area(d1, d2, 1.2) * length  # tests/cli/fillet_math.py
assert abs(vol - exact) < 1e-9 * exact, (vol, exact)
assert r["valid"], "every cell valid"
print(kind, "fillet volume", vol, "exact", exact)
PY
}

corner '"distance": [1, 0.5], "section": "flend", "dip": 0'
"$trivox" build "$tmp/corner.json" -o "$tmp/chamfer.json" --json > "$tmp/build.out"
check "$tmp/build.out" chamfer
# Just under the chamfer plane (x - 2) / 1 + z / 0.5 = 1 at y = 2: in the fillet; just over: void.
"$trivox" locate "$tmp/chamfer.json" --xyz 2.5,2,0.24 --json > "$tmp/in.out"
"$trivox" locate "$tmp/chamfer.json" --xyz 2.5,2,0.26 --json > "$tmp/out.out"
"$py" - "$tmp/in.out" "$tmp/out.out" <<'PY'
import sys, json
a, b = json.load(open(sys.argv[1])), json.load(open(sys.argv[2]))
assert a["inside"] and a["cell"].startswith("fillet.1"), a
assert not b["inside"], b
# Sec. 7.1: the colour blends the floor's red and the wall's blue (the blend is convex).
p = a["properties"]
assert 0.0 <= p["r"] <= 1.0 and abs(p["r"] + p["b"] - 1) < 1e-9 and p["g"] == 0, a
PY

# The slicer sees the fillet: the union of the boxes (16 + 17.5 - 2 overlapping) plus the
# chamfer prism (1) is 32.5 mm^3; without the fillet it would be 31.5.
"$trivox" slice "$tmp/chamfer.json" -o "$tmp/stack" --dpi 300,300 --layer 0.05 --progress never --json > "$tmp/slice.out"
"$py" - "$tmp/slice.out" <<'PY'
import sys, json
j = json.load(open(sys.argv[1]))
vol = sum(m["volume_mm3"] for m in j["materials"])
assert abs(vol - 32.5) < 0.005 * 32.5, vol
PY

corner '"distance": [1, 0.5], "tau": 1.2'
"$trivox" build "$tmp/corner.json" -o "$tmp/hermite.json" --json > "$tmp/build.out"
check "$tmp/build.out" hermite
"$trivox" build "$tmp/corner.json" -o "$tmp/hermite2.json" > "$tmp/human.out"
grep -q "fillet.1 .*floor.w1/wall.u1 .*positive .*composed" "$tmp/human.out" || { cat "$tmp/human.out"; exit 1; }

# The shipped models: exact composition for the Bezier spheres, fitted sub-regions on the
# B-spline sphere and cone.
for m in fillet_spheres:composed fillet_sphere_cone:fitted; do
  "$trivox" build "models/${m%%:*}.json" -o "$tmp/m.json" --force --json > "$tmp/m.out"
  "$py" - "$tmp/m.out" "${m##*:}" <<'PY'
import sys, json
r = json.load(open(sys.argv[1]))
(f,) = r["fillets"]
assert f["jacobian"] == "positive", f
assert all(c == (sys.argv[2] == "composed") for c in f["composed"]), f["composed"]
assert max(f["gap"]) < 1e-5 and max(f["g1_angle"]) < 1e-5, f
assert r["valid"]
PY
done

# A bridge (Flends Sec. III) between disjoint boxes, the second lifted by 1: its sections are
# translates, so its volume is 1 x 2 x 1 = 2; at its centre the colour is half of each.
cat > "$tmp/bridge.json" <<'EOF'
{ "trivox": 1, "units": "mm", "properties": ["r", "g", "b"],
  "cells": [
    {"name": "a", "primitive": {"type": "box", "min": [0, 0, 0], "max": [1, 1, 1]}, "field": {"constant": [1, 0, 0]}},
    {"name": "b", "primitive": {"type": "box", "min": [3, 0, 1], "max": [4, 1, 2]}, "field": {"constant": [0, 0, 1]}}
  ],
  "operations": [{"op": "fillet", "name": "link", "between": [{"cell": "a", "face": "u1"}, {"cell": "b", "face": "u0"}],
                  "bridge": true, "dip": 0.4}] }
EOF
"$trivox" build "$tmp/bridge.json" -o "$tmp/bridge-model.json" --json > "$tmp/build.out"
"$trivox" locate "$tmp/bridge-model.json" --xyz 2,0.5,1 --json > "$tmp/loc.out"
"$py" - "$tmp/build.out" "$tmp/loc.out" <<'PY'
import sys, json
r, loc = json.load(open(sys.argv[1])), json.load(open(sys.argv[2]))
(b,) = r["bridges"]
assert b["cell"] == "link.1" and b["orientation"] == "as is", b
assert max(b["g1_angle"]) < 1e-9 and b["min_jacobian"] > 0, b
(cell,) = [c for c in r["cells"] if c["name"] == "link.1"]
assert cell["verdict"] == "valid" and abs(cell["volume"] - 2.0) < 1e-12, cell
assert loc["cell"] == "link.1", loc
p = loc["properties"]
assert abs(p["r"] - 0.5) < 1e-9 and abs(p["b"] - 0.5) < 1e-9, p
PY
sed -i 's/"bridge": true, "dip": 0.4/"bridge": true, "distance": 1/' "$tmp/bridge.json"
expect_fail 'bridge.json: /operations/0/distance: "distance" with "bridge": true; expected only' \
  "$trivox" build "$tmp/bridge.json" -o "$tmp/x.json"

# Bad fillets: exit 2, the operation's place and what is wrong.
corner '"distance": [2.5, 0.5]'
expect_fail "corner.json: /operations/0: rails: the rail on face 1 at distance 2.5 leaves the face" \
  "$trivox" build "$tmp/corner.json" -o "$tmp/x.json"
corner '"distance": 1, "tau": 20'
expect_fail "corner.json: /operations/0/tau: tau 20.0; expected a value in (0, 10]" "$trivox" build "$tmp/corner.json" -o "$tmp/x.json"
corner '"distance": 1'
sed -i 's/"min": \[1, -0.5, -0.5\], "max": \[2, 4.5, 3\]/"min": [1, -0.5, 1], "max": [2, 4.5, 3]/' "$tmp/corner.json"
expect_fail "corner.json: /operations/0: fillet: the faces do not intersect" "$trivox" build "$tmp/corner.json" -o "$tmp/x.json"
corner '"distance": 1'
sed -i 's/\[{"cell": "floor", "face": "w1"}, {"cell": "wall", "face": "u1"}\]/["floor", "wall"]/' "$tmp/corner.json"
expect_fail '/operations/0/between: "floor" and "wall" intersect on several pairs of faces (' \
  "$trivox" build "$tmp/corner.json" -o "$tmp/x.json"
# A ball resting on a box touches it at one point: no curve to fillet along.
cat > "$tmp/touch.json" <<'EOF'
{ "trivox": 1, "units": "mm", "properties": ["r"],
  "cells": [
    {"name": "a", "primitive": {"type": "sphere", "center": [0, 0, 0], "radius": 5}, "field": {"constant": [1]}},
    {"name": "b", "primitive": {"type": "box", "min": [5, -3, -3], "max": [8, 3, 3]}, "field": {"constant": [0]}}
  ],
  "operations": [{"op": "fillet", "between": [{"cell": "a.x1", "face": "w1"}, {"cell": "b", "face": "u0"}], "distance": 1}] }
EOF
expect_fail "touch.json: /operations/0: fillet: the faces touch at a point" "$trivox" build "$tmp/touch.json" -o "$tmp/x.json"
[ ! -e "$tmp/x.json" ]
# A tangent 6 times the width folds the Hermite section: reported (exit 1), not written.
corner '"distance": [1, 0.5], "tau": 6'
expect_failed '/operations/0: fillet 1 of "fillet": det J changes sign inside' "$tmp/x.json" \
  "$trivox" build "$tmp/corner.json" -o "$tmp/x.json"
echo "fillet: ok"
