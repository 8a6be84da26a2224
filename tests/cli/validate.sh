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
echo "validate: ok"
