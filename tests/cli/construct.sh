#!/usr/bin/env bash
# End-to-end: `trivox construct` (construct/constructors.hpp, construct/kernel_construct.hpp).
# Truths: the Coons patch of the unit square's four sides is the identity map (det J = 1); an
# L-shaped boundary whose Coons patch folds (det J < 0 where the top curve runs down, derived in
# the comment below) has the kernel [0,1]^2, so the kernel-based Boolean sum must succeed, keep
# the four boundary curves (checked by Python from the written control points: an order-2
# boundary's control points are the polyline's vertices) and give det J >= 0 at sampled points
# (Python evaluates the written surface independently with Cox-de Boor); the volumetric
# Boolean sum of a box's six faces has volume 6 = 1 x 2 x 3; bad inputs exit 2 naming the place.
set -euo pipefail
source tests/cli/lib.bash "$@"

"$py" - "$tmp" <<'PY'
import sys, json
d = sys.argv[1]
def line(a, b):
    return {"orders": [2], "knots": [[0, 0, 1, 1]], "points": [a, b]}
def poly(pts):
    n = len(pts)
    knots = [0.0] + [i / (n - 1) for i in range(n)] + [1.0]
    return {"orders": [2], "knots": [knots], "points": pts}
# Unit square: bottom, top, left, right.
json.dump({"trivox": 1, "op": "boolean_sum",
           "curves": [line([0, 0], [1, 0]), line([0, 1], [1, 1]), line([0, 0], [0, 1]), line([1, 0], [1, 1])]},
          open(d + "/square.json", "w"))
# L shape: bottom (0,0)-(2,0), right (2,0)-(2,1), left (0,0)-(0,2), top (0,2)-(1,2)-(1,1)-(2,1).
# Coons: at v = 1, S_u = T'(u) = (0, -3) for u in (1/3, 2/3) and S_v = T(u) - B(u); at u = 0.6
# T = (1, 1.2), B = (1.2, 0): det[S_u, S_v] = 0 * 1.2 - (-3)(-0.2) = -0.6 < 0, while at u = 0.4
# it is +0.6: the regular construction is invalid.
json.dump({"trivox": 1, "op": "boolean_sum",
           "curves": [line([0, 0], [2, 0]), poly([[0, 2], [1, 2], [1, 1], [2, 1]]),
                      line([0, 0], [0, 2]), line([2, 0], [2, 1])]},
          open(d + "/ell.json", "w"))
# Six faces of the box [0,1] x [0,2] x [0,3], each parametrised by the two other directions in
# increasing order (u0 u1 v0 v1 w0 w1).
def face(fixed, val):
    pts = []
    for b in range(2):
        for a in range(2):
            p = [0.0, 0.0, 0.0]
            free = [k for k in range(3) if k != fixed]
            p[fixed] = val * [1, 2, 3][fixed]
            p[free[0]] = a * [1, 2, 3][free[0]]
            p[free[1]] = b * [1, 2, 3][free[1]]
            pts.append(p)
    return {"orders": [2, 2], "knots": [[0, 0, 1, 1], [0, 0, 1, 1]], "points": pts}
json.dump({"trivox": 1, "op": "boolean_sum", "surfaces": [face(k, v) for k in range(3) for v in (0, 1)]},
          open(d + "/box.json", "w"))
json.dump({"trivox": 1, "op": "extrude", "curves": [line([0, 0], [3, 0])], "vector": [0, 2]},
          open(d + "/extrude.json", "w"))
json.dump({"trivox": 1, "op": "boolean_sum",
           "curves": [line([0, 0], [1, 0]), line([0, 1], [1, 1]), line([0, 0], [0, 1]), poly([[1, 0], [-0.5, 0.5], [1, 1]])]},
          open(d + "/crossing.json", "w"))
# A box whose top face (w1) dips through its bottom face (w0): the two cross inside both.
faces = [face(k, v) for k in range(3) for v in (0, 1)]
top = faces[5]
top["orders"] = [3, 3]
top["knots"] = [[0, 0, 0, 1, 1, 1], [0, 0, 0, 1, 1, 1]]
top["points"] = [[a * 0.5, b * 1.0, (-20.0 if (a, b) == (1, 1) else 3.0)] for b in range(3) for a in range(3)]
json.dump({"trivox": 1, "op": "boolean_sum", "surfaces": faces}, open(d + "/dip.json", "w"))
json.dump({"trivox": 1, "op": "pizza", "curves": []}, open(d + "/badop.json", "w"))
json.dump({"trivox": 1, "op": "ruled", "curves": [line([0, 0], [1, 0])]}, open(d + "/fewer.json", "w"))
json.dump({"trivox": 1, "op": "boolean_sum",
           "curves": [line([0, 0], [1, 0]), line([0, 1], [1, 1]), line([0, 0], [0, 1]), line([1.5, 0], [1, 1])]},
          open(d + "/gap.json", "w"))
json.dump({"trivox": 1, "op": "ruled", "curves": [line([0, 0], [1, 0]), line([0, 1, 0], [1, 1, 0])]},
          open(d + "/dims.json", "w"))
PY

# The unit square: regular Boolean sum, valid, det J = 1.
"$trivox" construct "$tmp/square.json" --json > "$tmp/sq.out"
"$py" - "$tmp/sq.out" <<'PY'
import sys, json
r = json.load(open(sys.argv[1]))
assert r["regular_valid"] is True and r["valid"] is True and r["kernel"] is None and r["iterations"] == 0, r
assert r["orders"] == [2, 2] and r["counts"] == [2, 2], r
assert abs(r["min_jacobian"] - 1) < 1e-12 and abs(r["max_jacobian"] - 1) < 1e-12, r
PY

# The L shape: the regular construction is invalid (exit 1, nothing written) ...
set +e
"$trivox" construct "$tmp/ell.json" --json -o "$tmp/ell-regular.json" > "$tmp/ell.out" 2> "$tmp/ell.err"
rc=$?
set -e
[ $rc -eq 1 ] || { echo "regular L: expected exit 1, got $rc"; cat "$tmp/ell.err"; exit 1; }
grep -q "try --kernel" "$tmp/ell.err"
[ ! -e "$tmp/ell-regular.json" ]
"$py" -c "import json,sys; r=json.load(open('$tmp/ell.out')); assert r['valid'] is False and r['regular_valid'] is False, r"

# ... the kernel-based one succeeds with the kernel point inside the kernel [0,1]^2.
"$trivox" construct "$tmp/ell.json" --kernel --json -o "$tmp/ell-kernel.json" > "$tmp/ellk.out"
"$py" - "$tmp/ellk.out" "$tmp/ell-kernel.json" <<'PY'
import sys, json
import numpy as np
r = json.load(open(sys.argv[1]))
assert r["regular_valid"] is False and r["valid"] is True, r
k = r["kernel"]
assert 0 < k[0] < 1 and 0 < k[1] < 1, k
s = json.load(open(sys.argv[2]))["surfaces"][0]
(ou, ov), (ku, kv) = s["orders"], s["knots"]
nu, nv = len(ku) - ou, len(kv) - ov
P = np.array(s["points"], dtype=float).reshape(nv, nu, -1)

def basis(knots, order, t):
    # Cox-de Boor, the last span closed on the right.
    n = len(knots) - order
    N = np.array([1.0 if (knots[i] <= t < knots[i + 1]) or (t == knots[-1] and knots[i] < knots[i + 1] == knots[-1])
                  else 0.0 for i in range(len(knots) - 1)])
    for p in range(1, order):
        M = np.zeros(len(knots) - 1 - p)
        for i in range(len(M)):
            a = knots[i + p] - knots[i]
            b = knots[i + p + 1] - knots[i + 1]
            M[i] = (0 if a == 0 else (t - knots[i]) / a * N[i]) + (0 if b == 0 else (knots[i + p + 1] - t) / b * N[i + 1])
        N = M
    return N[:n]

def ev(u, v):
    return np.einsum("i,j,jik->k", basis(ku, ou, u), basis(kv, ov, v), P)

# Boundaries kept: the corners of the boundary rows are the L's vertices.
assert np.allclose(P[0, 0, :2], [0, 0]) and np.allclose(P[0, -1, :2], [2, 0]), P[0]
assert np.allclose(P[-1, 0, :2], [0, 2]) and np.allclose(P[-1, -1, :2], [2, 1]), P[-1]
for t in np.linspace(0, 1, 11):
    assert np.allclose(ev(t, 0.0)[:2], [2 * t, 0], atol=1e-12), (t, ev(t, 0.0))
    assert np.allclose(ev(0.0, t)[:2], [0, 2 * t], atol=1e-12), (t, ev(0.0, t))
    assert np.allclose(ev(1.0, t)[:2], [2, t], atol=1e-12), (t, ev(1.0, t))
    top = ev(t, 1.0)[:2]
    exp = [3 * t, 2] if t <= 1 / 3 else ([1, 2 - 3 * (t - 1 / 3)] if t <= 2 / 3 else [1 + 3 * (t - 2 / 3), 1])
    assert np.allclose(top, exp, atol=1e-12), (t, top, exp)
# det J >= 0 by central differences at interior points (never clearly negative).
h = 1e-6
for u in np.linspace(0.02, 0.98, 25):
    for v in np.linspace(0.02, 0.98, 25):
        du = (ev(u + h, v) - ev(u - h, v))[:2] / (2 * h)
        dv = (ev(u, v + h) - ev(u, v - h))[:2] / (2 * h)
        assert du[0] * dv[1] - du[1] * dv[0] > -1e-6, (u, v)
PY
grep -q '"valid": true' "$tmp/ellk.out"
"$trivox" construct "$tmp/ell.json" --kernel > "$tmp/ellk.txt"
grep -q "kernel point" "$tmp/ellk.txt"

# Volumetric Boolean sum of a box's six faces: the box itself, det J = 6.
"$trivox" construct "$tmp/box.json" --json -o "$tmp/box-out.json" > "$tmp/box.out"
"$py" - "$tmp/box.out" "$tmp/box-out.json" <<'PY'
import sys, json
r = json.load(open(sys.argv[1]))
assert r["result"] == "trivariate" and r["valid"] is True, r
assert abs(r["min_jacobian"] - 6) < 1e-9 and abs(r["max_jacobian"] - 6) < 1e-9, r
t = json.load(open(sys.argv[2]))["trivariates"][0]
assert t["orders"] == [2, 2, 2], t
PY
# Extrusion of a segment of length 3 by (0, 2): det J = 6 everywhere.
"$trivox" construct "$tmp/extrude.json" --json > "$tmp/ex.out"
"$py" -c "import json; r=json.load(open('$tmp/ex.out')); assert r['valid'] and abs(r['min_jacobian'] - 6) < 1e-12 and abs(r['max_jacobian'] - 6) < 1e-12, r"
# An existing output is kept unless --force.
expect_fail "output file exists" "$trivox" construct "$tmp/box.json" -o "$tmp/box-out.json"
"$trivox" construct "$tmp/box.json" -o "$tmp/box-out.json" --force > /dev/null

# Bad input: exit 2 naming the place and what was expected.
expect_fail '/op: unknown constructor "pizza"; expected one of boolean_sum' "$trivox" construct "$tmp/badop.json"
expect_fail '/curves: 1 curve for "ruled"; expected 2 curves' "$trivox" construct "$tmp/fewer.json"
expect_fail 'bottom(1) and right(0) are 0.5 apart' "$trivox" construct "$tmp/gap.json"
expect_fail '/curves/1/points/0: 3 coordinates; expected 2 (as in /curves/0)' "$trivox" construct "$tmp/dims.json"
expect_fail '/curves/2 and /curves/3 cross near (0, 0.3333' "$trivox" construct "$tmp/crossing.json"
expect_fail '/surfaces/4 and /surfaces/5 cross near' "$trivox" construct "$tmp/dip.json"
expect_fail 'no such file' "$trivox" construct "$tmp/missing.json"
echo '{"trivox": 1, "op": "ruled", "curves": [' > "$tmp/broken.json"
expect_fail 'malformed JSON' "$trivox" construct "$tmp/broken.json"
expect_fail 'expected boolean_sum, half_boolean_sum or ruled' "$trivox" construct "$tmp/extrude.json" --kernel
expect_fail 'expected refine or elevate\|--add-dof' "$trivox" construct "$tmp/ell.json" --kernel --add-dof wiggle
echo "construct: all checks passed"
