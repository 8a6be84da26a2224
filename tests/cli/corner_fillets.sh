#!/usr/bin/env bash
# End-to-end: fillets over several faces with C1 corners (Masalha et al. 2021, Sec. 6) and the
# singular bridging fillets at the convex corners (Sec. 6.1), built by `trivox build`. Truths:
# - a column [-1,1]^2 x [-1,3] through a plate z <= 0 (boxes): C is the square footprint, four
#   straight pieces and four convex corners at the column's vertical edges. The pieces are the
#   Hermite section swept along 2 mm each, the bridges the section turned a quarter turn about the
#   edge (Pappus: (pi/2) oint X^2/2 dZ, tests/cli/fillet_math.py), so the ring's volume is exact;
#   a point by an edge, outside both boxes and inside the ring's corner, is in a bridge cell with
#   the bridges and in no cell with "corners": "open" (the gap of Fig. 12 (c));
# - the box and cylinder of Fig. 12 (models/box_cylinder.json): a cylinder of radius 8 whose axis
#   lies in the box's face x = 0, through its top and bottom faces: C has eight pieces (three
#   cylinder cells' sides against three box faces) and four convex corners at (0, +-8, 0) and
#   (0, +-8, -10), where the box's edges (along y, perpendicular to the cylinder there) cross
#   the cylinder; p and q are 2 from o on the cylinder, r = o +- (0, 2, 0) on the edge; det J > 0
#   inside; the bridges are pinned to their neighbours' end sections: glue at rounding level,
#   no property jump, and `trivox validate` finds no cell invalid;
# - the turned column through a plate of two cells (below): B_d across the plate's seam, the
#   bridges there in two parts (Fig. 12 (d));
# - the concave corner of an L-shaped prism on a plate (models/l_notch.json, below): stitched;
# - bad input exits 2 naming the place: a concave corner whose rails cross beyond the pieces,
#   faces that do not meet, "corners" without face lists, the flend section or
#   the VBS construction with corners, a bad face name in a list.
set -euo pipefail
source tests/cli/lib.bash "$@"

column_scene() {  # column_scene FILE EXTRA-FIELDS [SIDE-2]: the column's four sides by default
  local side2=${3:-'{"cell": "column", "face": "u0"}, {"cell": "column", "face": "v0"},
                 {"cell": "column", "face": "u1"}, {"cell": "column", "face": "v1"}'}
  cat > "$1" <<EOF
{ "trivox": 1, "units": "mm", "properties": ["r", "g", "b"],
  "cells": [
    {"name": "plate", "primitive": {"type": "box", "min": [-4, -4, -2], "max": [4, 4, 0]}, "field": {"constant": [1, 0, 0]}},
    {"name": "column", "primitive": {"type": "box", "min": [-1, -1, -1], "max": [1, 1, 3]}, "field": {"constant": [0, 0, 1]}}
  ],
  "operations": [{"op": "fillet", "name": "ring",
    "between": [[{"cell": "plate", "face": "w1"}],
                [$side2]],
    "distance": [1.0, 0.5], "tau": 1.0$2}] }
EOF
}

column_scene "$tmp/column.json" ""
"$trivox" build "$tmp/column.json" -o "$tmp/column.model.json" --json > "$tmp/column.build.json"
"$py" - "$tmp/column.build.json" <<'PY'
import sys, json, math
sys.path.insert(0, "tests/cli")
from fillet_math import hermite_area, hermite_moment
r = json.load(open(sys.argv[1]))
assert r["valid"], "every cell valid"
d1, d2, tau = 1.0, 0.5, 1.0
f, k = r["fillets"], r["corners"]
assert len(f) == 4 and len(k) == 4, (len(f), len(k))
for c in k:
    o, p, q, rr = (c[x] for x in "opqr")
    assert abs(abs(o[0]) - 1) < 1e-9 and abs(abs(o[1]) - 1) < 1e-9 and abs(o[2]) < 1e-9, o
    assert abs(math.dist(o, p) - d1) < 1e-9 and abs(math.dist(o, q) - d1) < 1e-9, (o, p, q)
    assert math.dist(rr, [o[0], o[1], o[2] + d2]) < 1e-9, (o, rr)
    assert abs(c["angle"] - math.pi / 2) < 1e-9, c["angle"]
    assert c["gap_face"] == "plate/w1" and c["edge_face"].startswith("column/"), c
    assert c["jacobian"] == "positive" and c["min_jacobian"] > 0, c
    assert max(c["glue"]) < 1e-12 and max(c["glue_before"]) < 1e-5 and c["g1_angle"] < 1e-5, (c["glue"], c["g1_angle"])
    assert max(c["property_jump"]) < 1e-12, c["property_jump"]
vol = {x["name"]: x["volume"] for x in r["cells"]}
pieces = sum(v for n, v in vol.items() if n.startswith("ring.") and not n.startswith("ring.c"))
bridges = sum(v for n, v in vol.items() if n.startswith("ring.c"))
want_p = 4 * 2.0 * hermite_area(d1, d2, tau)
want_b = 4 * math.pi / 2 * hermite_moment(d1, d2, tau)
assert abs(pieces - want_p) < 1e-9 * want_p, (pieces, want_p)
assert abs(bridges - want_b) < 1e-5 * want_b, (bridges, want_b)
print(f"column ring: pieces {pieces:.9f} (exact {want_p:.9f}), bridges {bridges:.9f} (Pappus {want_b:.9f})")
PY
# By the edge x = y = 1: 0.2 out along the diagonal and 0.1 up lies in the bridge, and in the
# gap without it.
loc() { "$trivox" locate "$1" --xyz "$2" --json | "$py" -c 'import sys, json; d = json.load(sys.stdin); print(d["cell"] if d["inside"] else "-")'; }
cell=$(loc "$tmp/column.model.json" 1.1414,1.1414,0.1)
case $cell in ring.c*) ;; *) echo "by the edge: in '$cell', expected a bridge cell ring.c*"; exit 1 ;; esac
column_scene "$tmp/open.json" ', "corners": "open"'
"$trivox" build "$tmp/open.json" -o "$tmp/open.model.json" --json > "$tmp/open.build.json"
cell=$(loc "$tmp/open.model.json" 1.1414,1.1414,0.1)
[ "$cell" = - ] || { echo "open corners: the gap point is in '$cell'"; exit 1; }
"$py" -c 'import sys, json; r = json.load(open(sys.argv[1])); assert r["corners"] == [] and len(r["fillets"]) == 4' "$tmp/open.build.json"

# Fig. 12 (d): B_d across a seam. The column turned 45 degrees about z (an explicit trilinear
# cell: edges at (+-sqrt 2, 0) and (0, +-sqrt 2)) through a plate of two box cells joined along
# x = 0: at the corners (0, +-sqrt 2, 0) p and q lie on the two cells and B_d crosses the seam at
# s = (0, +-(sqrt 2 + 1), 0); the bridge there is built in two parts, one per plate cell, an eighth
# turn each (Pappus), glued to each other at rounding level; the corners (+-sqrt 2, 0, 0) are
# inside one cell (a quarter turn). The whole ring's bridges: four quarter turns, as unturned.
"$py" - "$tmp/seam.json" <<'PY'
import sys, json, math
c = math.sqrt(0.5)
pts = [[c * (x - y), c * (x + y), z, 0, 0, 1] for z in (-1, 3) for y in (-1, 1) for x in (-1, 1)]
kv = [0, 0, 1, 1]
json.dump({"trivox": 1, "units": "mm", "properties": ["r", "g", "b"],
  "cells": [
    {"name": "west", "primitive": {"type": "box", "min": [-4, -4, -2], "max": [0, 4, 0]}, "field": {"constant": [1, 0, 0]}},
    {"name": "east", "primitive": {"type": "box", "min": [0, -4, -2], "max": [4, 4, 0]}, "field": {"constant": [1, 0, 0]}},
    {"name": "column", "trivariate": {"orders": [2, 2, 2], "knots": [kv, kv, kv], "points": pts}}],
  "operations": [{"op": "fillet", "name": "ring",
    "between": [[{"cell": "west", "face": "w1"}, {"cell": "east", "face": "w1"}],
                [{"cell": "column", "face": f} for f in ("u0", "v0", "u1", "v1")]],
    "distance": [1.0, 0.5], "tau": 1.0}]}, open(sys.argv[1], "w"))
PY
"$trivox" build "$tmp/seam.json" -o "$tmp/seam.model.json" --json > "$tmp/seam.build.json"
"$py" - "$tmp/seam.build.json" <<'PY'
import sys, json, math
sys.path.insert(0, "tests/cli")
from fillet_math import hermite_area, hermite_moment
r = json.load(open(sys.argv[1]))
assert r["valid"], "every cell valid"
d1, d2, tau = 1.0, 0.5, 1.0
quarter = math.pi / 2 * hermite_moment(d1, d2, tau)
k = r["corners"]
assert len(r["fillets"]) == 4 and len(k) == 6, (len(r["fillets"]), len(k))
parts = 0
for c in k:
    o = c["o"]
    v = sum(c["cell_volume"])
    assert c["jacobian"] == "positive" and c["min_jacobian"] > 0, c
    assert max(c["glue"]) < 1e-12 and max(c["property_jump"]) < 1e-12, (c["glue"], c["property_jump"])
    if abs(o[0]) > 1e-9:
        assert c["part"] == -1 and abs(v - quarter) < 1e-5 * quarter, (o, c["part"], v, quarter)
        continue
    parts += 1
    assert c["part"] in (0, 1) and abs(v - quarter / 2) < 1e-5 * quarter, (o, c["part"], v, quarter / 2)
    assert c["gap_face"] in ("west/w1", "east/w1"), c["gap_face"]
    s = c["seam"]
    want = [0, o[1] + math.copysign(d1, o[1]), 0]
    assert all(math.dist(x, want) < 1e-9 for x in s["point"]), (s["point"], want)
    assert s["glue"] < 1e-12 and s["glue_before"] < 1e-5 and s["gap"] < 1e-9 and s["angle"] < 1e-12, s
    print(f"seam corner {o[1]:+.4f}, part {c['part']} on {c['gap_face']}: volume {v:.9f} (Pappus/2 {quarter / 2:.9f}), "
          f"seam glue {s['glue']:.1e} (before {s['glue_before']:.1e})")
assert parts == 4, parts
vol = {x["name"]: x["volume"] for x in r["cells"]}
bridges = sum(v for n, v in vol.items() if n.startswith("ring.c"))
assert abs(bridges - 4 * quarter) < 1e-5 * 4 * quarter, (bridges, 4 * quarter)
print(f"seam ring: bridges {bridges:.9f} (4 quarter turns {4 * quarter:.9f})")
PY
# Bad input: the east cell ends at y = 2.2, past p but before the seam point (0, sqrt 2 + 1, 0).
"$py" -c 'import sys, json; m = json.load(open(sys.argv[1])); m["cells"][1]["primitive"]["max"] = [4, 2.2, 0]; json.dump(m, open(sys.argv[2], "w"))' \
  "$tmp/seam.json" "$tmp/bad.json"
expect_fail '/operations/0: fillet corner at (.*/w1 x column.*/w1 x column.*seam through' \
  "$trivox" build "$tmp/bad.json" -o "$tmp/bad.model.json"

# Fig. 12: the box and the cylinder.
"$trivox" build models/box_cylinder.json -o "$tmp/bc.model.json" --json > "$tmp/bc.build.json"
"$py" - "$tmp/bc.build.json" <<'PY'
import sys, json, math
r = json.load(open(sys.argv[1]))
assert r["valid"], "every cell valid"
f, k = r["fillets"], r["corners"]
assert len(f) == 8 and len(k) == 4, (len(f), len(k))
for x in f:
    assert x["jacobian"] == "positive", (x["between"], x["jacobian"])
    assert max(x["gap"]) < 1e-4 and max(x["g1_angle"]) < 1e-3, (x["between"], x["gap"], x["g1_angle"])
seen = set()
for c in k:
    o, p, q, rr = (c[x] for x in "opqr")
    # The cylinder is the cubic interpolant of the circle, within 2e-4 r (construct/primitives.hpp).
    assert abs(o[0]) < 1e-5 and abs(abs(o[1]) - 8) < 2e-3 and min(abs(o[2]), abs(o[2] + 10)) < 1e-5, o
    seen.add((round(o[1]), round(o[2])))
    assert abs(math.dist(o, p) - 2) < 1e-4 and abs(math.dist(o, q) - 2) < 1e-4, (o, p, q)
    assert math.dist(rr, [0, o[1] + math.copysign(2, o[1]), o[2]]) < 1e-4, (o, rr)
    assert c["gap_face"].startswith("post.y") and c["edge_face"].startswith("block/"), c
    assert abs(c["angle"] - math.pi / 2) < 1e-2, c["angle"]
    assert c["jacobian"] == "positive" and c["min_jacobian"] > 0, c
    assert max(c["end_error"], c["o_error"], c["r_error"], c["radius_error"]) < 1e-4, c
    # Pinned to the neighbours' end sections (Sec. 6.1's C0 glue): rounding level, far below the
    # fillet tolerance 1e-7 * diagonal (5.9e-6); before pinning, the two fits' difference.
    tol = 5.9e-6  # 1e-7 of the listed cells' bounding-box diagonal
    assert max(c["glue"]) < 1e-3 * tol and c["g1_angle"] < 1e-3, (c["glue"], c["g1_angle"])
    assert max(c["glue_before"]) < 1e-4 and max(c["property_jump"]) < 1e-12, (c["glue_before"], c["property_jump"])
    print(f"corner {o[0]:+.4f} {o[1]:+.4f} {o[2]:+.4f}: glue {max(c['glue']):.2e} (before pinning "
          f"{max(c['glue_before']):.2e}), property jump {max(c['property_jump_before']):.2e} -> "
          f"{max(c['property_jump']):.2e}, G1 {c['g1_angle']:.2e}, "
          f"det J {c['min_jacobian']:.3e}..{c['max_jacobian']:.3e}, volume {sum(c['cell_volume']):.6f}")
assert seen == {(8, 0), (-8, 0), (8, -10), (-8, -10)}, seen
PY
# Pinning keeps the bridges' singular structure exact: no cell is found invalid (det J < 0 at a
# point), the segment halves are proven degenerate (det J = 0 on the edge o r, > 0 inside).
"$trivox" validate "$tmp/bc.model.json" --json > "$tmp/bc.validate.json" || true
"$py" - "$tmp/bc.validate.json" <<'PY'
import sys, json
r = json.load(open(sys.argv[1]))
for c in r["cells"]:
    assert c["verdict"] != "invalid", c
    if c["name"].startswith("ring.c") and c["name"].endswith("b"):
        assert c["verdict"] == "degenerate", c
PY
# Next to the corner (0, 8, 0), outside the box (x > 0, z > 0) and the cylinder: in a bridge.
cell=$(loc "$tmp/bc.model.json" 0.3,8.3,0.3)
case $cell in ring.c*) ;; *) echo "by the corner (0, 8, 0): in '$cell', expected a bridge cell ring.c*"; exit 1 ;; esac

# Sec. 6's concave corner (models/l_notch.json): an L-shaped prism of three unit boxes on a plate,
# d = (0.5, 0.25), tau 1. C has eight unit pieces, five convex corners (bridged), two G1 joins
# and the concave corner o = (1, 1, 0), where the plate's rails y = 1.5 and x = 1.5 cross at
# x = (1.5, 1.5, 0) and the arms' rails meet on the reflex edge at r = (1, 1, 0.25). The two
# pieces there are clipped by the plane x = y through o, x and r and stitched: each is the
# Hermite section R swept along 1 and cut by that plane, int_R (1 - X) dA (X the distance from
# the edge); the six others are R swept along 1, the bridges Pappus' quarter turns.
"$trivox" build models/l_notch.json -o "$tmp/notch.model.json" --json > "$tmp/notch.build.json"
"$py" - "$tmp/notch.build.json" <<'PY'
import sys, json, math
sys.path.insert(0, "tests/cli")
from fillet_math import hermite_area, hermite_moment
r = json.load(open(sys.argv[1]))
assert r["valid"], "every cell valid"
d1, d2, tau = 0.5, 0.25, 1.0
area, moment = hermite_area(d1, d2, tau), hermite_moment(d1, d2, tau)
f, k, st = r["fillets"], r["corners"], r["stitches"]
assert len(f) == 8 and len(k) == 5 and len(st) == 1, (len(f), len(k), len(st))
s = st[0]
assert math.dist(s["o"], [1, 1, 0]) < 1e-9 and math.dist(s["x"], [1 + d1, 1 + d1, 0]) < 1e-9, s
assert math.dist(s["r"], [1, 1, d2]) < 1e-9 and abs(s["angle"] - math.pi / 2) < 1e-9, s
assert s["crossing_face"] == "plate/w1" and s["glue"] < 1e-12 and s["glue_before"] < 1e-6, s
for x in f:
    assert x["jacobian"] == "positive", (x["between"], x["jacobian"])
vol = {x["name"]: x["volume"] for x in r["cells"]}
clipped = {p.split(" x ")[1] for p in s["pieces"]}
assert clipped == {"arm_y/u1", "arm_x/v1"}, clipped
pieces = {}
for n, x in enumerate(f, 1):
    pieces[x["between"][1]["cell"] + "/" + x["between"][1]["face"]] = vol[f"ring.{n}a"] + vol[f"ring.{n}b"]
for face, v in pieces.items():
    want = area - moment if face in clipped else area
    assert abs(v - want) < 1e-6 * want, (face, v, want)
bridges = sum(v for n, v in vol.items() if n.startswith("ring.c"))
want_b = 5 * math.pi / 2 * moment
assert abs(bridges - want_b) < 1e-5 * want_b, (bridges, want_b)
for c in k:
    assert max(c["glue"]) < 1e-12 and c["jacobian"] == "positive", c
print(f"notch: clipped pieces {sorted(v for f_, v in pieces.items() if f_ in clipped)} (exact {area - moment:.9f}), "
      f"bridges {bridges:.9f} (Pappus {want_b:.9f}), stitch glue {s['glue']:.1e} (before {s['glue_before']:.1e})")
PY
# Between the arms, 0.05 above the plate on the diagonal: in a clipped piece's cell.
cell=$(loc "$tmp/notch.model.json" 1.1,1.1,0.05)
case $cell in ring.4?|ring.5?) ;; *) echo "in the notch: in '$cell', expected a clipped piece ring.4* or ring.5*"; exit 1 ;; esac

# Bad input: exit 2, the place named.
"$py" - models/l_notch.json "$tmp/bad.json" <<'PY'
import sys, json
m = json.load(open(sys.argv[1]))
op = m["operations"][0]
op["between"][1] = [{"cell": "arm_y", "face": "u1"}, {"cell": "arm_x", "face": "v1"}]
op["distance"] = [1.5, 0.25]  # the plate's rails would cross at (2.5, 2.5), past the unit arms
json.dump(m, open(sys.argv[2], "w"))
PY
expect_fail '/operations/0: fillet corner at (.*a concave corner whose rails on plate/w1 do not cross within both pieces' \
  "$trivox" build "$tmp/bad.json" -o "$tmp/bad.model.json"
column_scene "$tmp/bad.json" "" '{"cell": "column", "face": "w1"}, {"cell": "column", "face": "w0"}'
expect_fail '/operations/0: fillet across faces: the faces plate/w1 and column/w1, column/w0 do not intersect' \
  "$trivox" build "$tmp/bad.json" -o "$tmp/bad.model.json"
corner_scene "$tmp/bad.json" "$(fillet_op '"distance": 1, "corners": "bridge"')"
expect_fail '/operations/0/corners: "corners" with one face per side' "$trivox" build "$tmp/bad.json" -o "$tmp/bad.model.json"
column_scene "$tmp/bad.json" ', "section": "flend"'
expect_fail '/operations/0/section: .*Hermite section' "$trivox" build "$tmp/bad.json" -o "$tmp/bad.model.json"
column_scene "$tmp/bad.json" ', "construction": "vbs"'
expect_fail '/operations/0/construction: "construction" with a fillet over several faces' "$trivox" build "$tmp/bad.json" -o "$tmp/bad.model.json"
sed 's/"face": "v1"/"face": "side"/' "$tmp/column.json" > "$tmp/bad.json"
expect_fail '/operations/0/between/1/3/face: unknown face "side"' "$trivox" build "$tmp/bad.json" -o "$tmp/bad.model.json"
echo "corner_fillets: ok"
