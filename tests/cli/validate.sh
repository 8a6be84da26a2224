#!/usr/bin/env bash
# End-to-end: `trivox validate` (geom/validity.hpp). Truths: the shipped models' cells are valid
# (the Fichera corner's seven unit cubes have |det J| = 1 exactly); a trilinear cell
# with one corner pulled through the opposite one folds, and Python evaluates det J at the
# reported point independently (trilinear partials) to check its sign.
set -euo pipefail
source tests/cli/lib.bash "$@"

"$trivox" validate models/twisted_column.json > "$tmp/col.txt"
grep -q "every cell is valid" "$tmp/col.txt"
"$trivox" validate models/gismo/fichera.xml --json > "$tmp/f.json"
"$py" - "$tmp/f.json" <<'PY'
import sys, json
r = json.load(open(sys.argv[1]))
assert r["valid"] is True and len(r["cells"]) == 7, r
for c in r["cells"]:
    s = 1 if c["orientation"] == "right-handed" else -1
    assert c["valid"] and c["verdict"] == "valid", c
    assert abs(s * c["min_jacobian"] - 1) < 1e-8 and abs(s * c["max_jacobian"] - 1) < 1e-8, c
PY

# A folded trilinear cell: corner (1,1,1) moved to (-0.5,-0.5,-0.5).
"$py" - "$tmp/folded.json" <<'PY'
import sys, json
pts = []
for k in range(2):
    for j in range(2):
        for i in range(2):
            pts.append([-0.5, -0.5, -0.5] if (i, j, k) == (1, 1, 1) else [float(i), float(j), float(k)])
knots = [0.0, 0.0, 1.0, 1.0]
json.dump({"trivox": 1, "units": "mm", "properties": [],
           "cells": [{"name": "folded", "trivariate": {"orders": [2, 2, 2], "knots": [knots] * 3, "points": pts}}]},
          open(sys.argv[1], "w"))
PY
set +e
"$trivox" validate "$tmp/folded.json" --json > "$tmp/folded.out"
rc=$?
set -e
[ $rc -eq 1 ] || { echo "expected exit 1 for an invalid cell, got $rc"; exit 1; }
"$py" - "$tmp/folded.json" "$tmp/folded.out" <<'PY'
import sys, json
import numpy as np
m, r = json.load(open(sys.argv[1])), json.load(open(sys.argv[2]))
assert r["valid"] is False
c = r["cells"][0]
assert c["verdict"] == "invalid" and c["min_jacobian"] < 0 < c["max_jacobian"], c
u, v, w = c["invalid_at"]["uvw"]
P = np.array(m["cells"][0]["trivariate"]["points"]).reshape(2, 2, 2, 3)  # [k][j][i]
def d(axis):
    # trilinear partial along axis at (u, v, w)
    wts = {0: [(1 - u, u)], 1: [(1 - v, v)], 2: [(1 - w, w)]}
    g = np.zeros(3)
    for k in range(2):
        for j in range(2):
            for i in range(2):
                bu = [-1, 1][i] if axis == 0 else [1 - u, u][i]
                bv = [-1, 1][j] if axis == 1 else [1 - v, v][j]
                bw = [-1, 1][k] if axis == 2 else [1 - w, w][k]
                g += bu * bv * bw * P[k][j][i]
    return g
det = np.dot(d(0), np.cross(d(1), d(2)))
orient = 1 if c["orientation"] == "right-handed" else -1
assert det * orient <= 1e-9, (det, c)
assert abs(det - c["invalid_at"]["det"]) < 1e-9 * max(1, abs(det)), (det, c)
PY
expect_fail "no such file" "$trivox" validate "$tmp/none.json"

# Degenerate boundaries: the box and cylinder's ruled fillet cells have det J = 0 along their
# rails by construction (Masalha et al. 2021, Sec. 9) and > 0 inside: `degenerate`, not invalid. The
# reported point lies on the domain's boundary and det J there, evaluated independently by
# central differences of `trivox eval`, is 0 to the scale of the cell.
"$trivox" build models/box_cylinder.json -o "$tmp/bc.json" > /dev/null
"$trivox" validate "$tmp/bc.json" --json > "$tmp/bc.out" || true
"$py" - "$tmp/bc.out" "$trivox" "$tmp/bc.json" <<'PY'
import sys, json, subprocess
r = json.load(open(sys.argv[1]))
model = json.load(open(sys.argv[3]))
dom = {c["name"]: [(k[0], k[-1]) for k in c["trivariate"]["knots"]] for c in model["cells"]}
cells = {c["name"]: c for c in r["cells"]}
pieces = [n for n in cells if n.startswith("ring.") and not n.startswith("ring.c")]
assert len(pieces) == 16 or len(pieces) == 20, sorted(cells)
for n in pieces:
    c = cells[n]
    assert c["verdict"] == "degenerate" and c["valid"] is True, c
    t = c["degenerate_at"]["uvw"]
    assert any(x in dom[n][d] for d, x in enumerate(t)), (c, dom[n])
    assert 0 < c["zero_tolerance"] < 1e-8 * c["max_jacobian"], c
for n, c in cells.items():
    if not n.startswith("ring."):
        assert c["verdict"] == "valid", c
# det J at a degenerate point and just inside it, by differences of the evaluated map.
import numpy as np
c = cells[pieces[0]]
def X(t):
    out = subprocess.run([sys.argv[2], "eval", sys.argv[3], "--cell", pieces[0], "--uvw", ",".join(repr(v) for v in t), "--json"],
                         capture_output=True, text=True, check=True).stdout
    return np.array(json.loads(out)["point"])
def det(t, h=1e-6):
    cols = []
    for d in range(3):
        a, b = list(t), list(t)
        lo, hi = dom[pieces[0]][d]
        a[d] = min(hi, t[d] + h); b[d] = max(lo, t[d] - h)
        cols.append((X(a) - X(b)) / (a[d] - b[d]))
    return np.linalg.det(np.array(cols).T)
t = c["degenerate_at"]["uvw"]
assert abs(det(t)) < 1e-5 * c["max_jacobian"], (det(t), c)
inside = [0.5 * (x + 0.5 * (lo + hi)) for x, (lo, hi) in zip(t, dom[pieces[0]])]
assert det(inside) > 1e-3 * c["max_jacobian"], (det(inside), c)
PY
echo "validate: ok"
