#!/usr/bin/env bash
# End-to-end: `trivox build` (io/scene.hpp, construct/primitives.hpp). Truths: the analytic volumes
# of the five primitives of models/primitives.json (box 16 x 12 x 8; cylinder pi 6^2 14; frustum
# pi 12 (7^2 + 7 3 + 3^2) / 3; torus 2 pi^2 8 3^2; ball 4/3 pi 8^3), computed here in Python;
# their cell counts (1, 5, 5, 5, 7) and topology (22 + 22 + 22 + 24 + 6 V-surfaces, Massarwi & Elber
# 2016 Fig. 9; see tests/construct/test_primitives.cpp); a coarse slice's voxel count times the
# voxel volume is the total volume up to the voxelisation of the surface (3 percent at 35 dpi).
set -euo pipefail
source tests/cli/lib.bash "$@"

"$trivox" build models/primitives.json -o "$tmp/m.json" --json > "$tmp/build.json"
"$trivox" info "$tmp/m.json" --json > "$tmp/info.json"
"$trivox" validate "$tmp/m.json" > "$tmp/validate.txt"
grep -q "every cell is valid" "$tmp/validate.txt"
"$py" - "$tmp/build.json" "$tmp/info.json" <<'PY'
import sys, json, math
b, info = json.load(open(sys.argv[1])), json.load(open(sys.argv[2]))
pi = math.pi
exact = {"block": 16 * 12 * 8, "post": pi * 36 * 14, "funnel": pi * 12 * (49 + 21 + 9) / 3,
         "ring": 2 * pi * pi * 8 * 9, "ball": 4 / 3 * pi * 512}
cells = {"block": 1, "post": 5, "funnel": 5, "ring": 5, "ball": 7}
assert b["valid"] is True, b
assert [p["name"] for p in b["primitives"]] == list(exact), b["primitives"]
for p in b["primitives"]:
    e = exact[p["name"]]
    assert abs(p["exact_volume"] - e) < 1e-9 * e, p
    assert abs(p["volume"] - e) < 1e-3 * e, p
    assert p["cells"] == cells[p["name"]], p
assert all(p["field"]["exact"] for p in b["primitives"][:3]), b["primitives"]
for c in b["cells"]:
    assert c["valid"] and c["min_jacobian"] > 0, c
names = [c["name"] for c in info["cells"]]
assert names[:2] == ["block", "post.core"] and "ball.z1" in names and len(names) == 23, names
assert info["properties"] == ["r", "g", "b"]
assert abs(info["volume"] - sum(exact.values())) < 1e-3 * sum(exact.values()), info["volume"]
t = info["topology"]
assert t["v_cells"] == 23 and t["half_v_surfaces"] == 6 + 30 * 3 + 42, t
assert t["v_surfaces"] == 6 + 22 * 3 + 24, t
assert t["v_curves"] == 12 + 32 + 32 + 20 + 32 and t["v_points"] == 8 + 16 + 16 + 8 + 16, t
PY

# A coarse slice: voxels x voxel volume ~ the analytic volume.
"$trivox" slice "$tmp/m.json" -o "$tmp/slice" --dpi 35,35 --layer 0.725714 --threads 2 --progress never --json > "$tmp/slice.json"
"$py" - "$tmp/slice.json" <<'PY'
import sys, json, math
s = json.load(open(sys.argv[1]))
pi = math.pi
exact = 16 * 12 * 8 + pi * 36 * 14 + pi * 12 * 79 / 3 + 2 * pi * pi * 72 + 4 / 3 * pi * 512
p = s["grid"]["pitch"]
v = s["filled"] * p[0] * p[1] * p[2]
assert abs(v - exact) < 0.03 * exact, (v, exact)
PY

# The output is refused when it exists, replaced with --force.
expect_fail "expected a new model file name, or --force" "$trivox" build models/primitives.json -o "$tmp/m.json"
"$trivox" build models/primitives.json -o "$tmp/m.json" --force > "$tmp/human.txt"
grep -q "every cell is valid" "$tmp/human.txt"
grep -q "^ball  *sphere  *7" "$tmp/human.txt"

# Bad scenes exit 2 naming the file, the place and what was expected.
scene() { printf '{"trivox": 1, "properties": ["d"], "cells": [%s], "operations": [%s]}' "$1" "${2:-}" > "$tmp/s.json"; }
scene '{"name": "a", "primitive": {"type": "sphere", "center": [0,0,0], "radius": -1}, "field": {"constant": 1}}'
expect_fail "s.json: /cells/0/primitive: sphere radius -1; expected a positive" "$trivox" build "$tmp/s.json" -o "$tmp/x.json"
scene '{"name": "a", "primitive": {"type": "prism"}, "field": {"constant": 1}}'
expect_fail '/cells/0/primitive/type: unknown primitive type "prism"; expected "box"' "$trivox" build "$tmp/s.json" -o "$tmp/x.json"
scene '{"name": "a", "primitive": {"type": "box", "min": [0,0,0], "max": [1,1,1]}}'
expect_fail '/cells/0: missing "field"' "$trivox" build "$tmp/s.json" -o "$tmp/x.json"
scene '{"name": "a", "primitive": {"type": "box", "min": [0,0,0], "max": [1,1,1]}, "field": {"constant": 1}}' '{"op": "revolve", "name": "r"}'
expect_fail '/operations/0: missing "surfaces"' "$trivox" build "$tmp/s.json" -o "$tmp/x.json"
scene '{"name": "a", "primitive": {"type": "box", "min": [0,0,0], "max": [1,1,1]}, "field": {"constant": 1}}' '{"op": "ruled"}'
expect_fail '/operations/0: missing "name"; expected a constructor' "$trivox" build "$tmp/s.json" -o "$tmp/x.json"
scene '{"name": "a", "primitive": {"type": "box", "min": [0,0,0], "max": [1,1,1]}, "field": {"constant": 1}}' '{"op": "fillet"}'
expect_fail '/operations/0: missing "between"; expected a fillet' "$trivox" build "$tmp/s.json" -o "$tmp/x.json"
scene '{"name": "a", "primitive": {"type": "box", "min": [0,0,0], "max": [1,1,1]}, "field": {"constant": 1}}' '{"op": "smooth"}'
expect_fail '/operations/0/op: unknown operation "smooth"; expected one of "union", "intersection"' "$trivox" build "$tmp/s.json" -o "$tmp/x.json"
[ ! -e "$tmp/x.json" ]
# A scene is refused by commands that need a model, with the hint.
expect_fail "trivox build SCENE -o MODEL" "$trivox" info models/primitives.json

# revolve (Massarwi & Elber 2016, Sec. 3.2.2 item 3): the rectangle r in [2, 3], z in [0, 1] in the
# xz-plane turned about z by 360 degrees (and by 90) is the annulus of volume pi (3^2 - 2^2) (a
# quarter of it), within the revolution's tolerance (relative 1e-6 of the radius: volume error below
# 3 x 1e-6 relative); every cell valid; bad angles exit 2.
revolve_scene() {
  printf '{"trivox": 1, "properties": ["d"], "surfaces": [{"name": "rect", "surface": {"orders": [2, 2], "knots": [[0, 0, 1, 1], [0, 0, 1, 1]], "points": [[2, 0, 0, 5], [3, 0, 0, 5], [2, 0, 1, 5], [3, 0, 1, 5]]}}], "operations": [{"op": "revolve", "name": "ring", "surfaces": ["rect"], "axis": [0, 0, 1]%s}]}' "$1" > "$tmp/rev.json"
}
for angle in 360 90; do
  revolve_scene ", \"angle\": $angle"
  "$trivox" build "$tmp/rev.json" -o "$tmp/rev_model.json" --force --json > "$tmp/rev_build.json"
  "$py" - "$tmp/rev_build.json" "$angle" <<'PY'
import sys, json, math
b = json.load(open(sys.argv[1]))
angle = float(sys.argv[2])
exact = math.pi * (3 ** 2 - 2 ** 2) * angle / 360
vol = b["volume"]
assert b["valid"] is True, b["cells"]
assert abs(vol - exact) < 3e-6 * exact, (vol, exact)
print(f"revolve {angle:g} degrees: volume {vol:.9f}, exact {exact:.9f}")
PY
done
revolve_scene ', "angle": 400'
expect_fail '/operations/0/angle: angle 400.0; expected degrees in (0, 360]' "$trivox" build "$tmp/rev.json" -o "$tmp/x.json"
revolve_scene ', "tolerance": 0'
expect_fail '/operations/0/tolerance: tolerance 0.0; expected a relative tolerance' "$trivox" build "$tmp/rev.json" -o "$tmp/x.json"
echo "build: ok"
