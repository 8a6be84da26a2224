#!/usr/bin/env bash
# End-to-end: the scene fillet with "construction": "vbs" (Masalha et al. 2021, Sec. 3.2, Alg. 3,
# Appendix A) built by `trivox build`, read back by `trivox info` and `trivox locate`. Truths:
# - between a floor z <= 0 and a wall x <= 2 (boxes), the Hermite VBS fillet fills the region
#   between the faces and the cubic section: 4 times the area by Green's theorem (numpy), as the
#   ruled fillet does; its three cells meet S^_1, S^_2 and S_b with no gap, G1 below 1e-6 rad,
#   glue exactly (shared control points), det J > 0 inside every cell;
# - the 45-degree chamfer with legs 1: T_1 is the square [0, r]^2 x [0, 4] at C, r = 1 / (2 +
#   sqrt 2) (Eq. A.2 puts C_c at the incentre), T_2 and T_3 mirror images of volume (2 - 4 r^2) / 2;
#   `locate` finds points of the square in T_1, near the floor's rail in T_2, near the wall's in T_3,
#   and nothing beyond the chamfer plane;
# - the shipped models built both ways: the same region, so the same volume up to the seam of the
#   closed C (bound derived below), three cells per component with glue 0 and det J > 0;
# - bad values exit 2 naming the JSON pointer; a section the division cannot hold exits 1 and
#   writes nothing.
set -euo pipefail
source tests/cli/lib.bash "$@"

corner() { corner_scene "$tmp/corner.json" "$(fillet_op "$1")"; }  # corner FILLET-FIELDS

# The Hermite corner, tau 1.2, d = (1, 0.5).
corner '"distance": [1, 0.5], "tau": 1.2, "construction": "vbs"'
"$trivox" build "$tmp/corner.json" -o "$tmp/hermite.json" --json > "$tmp/build.out"
"$py" - "$tmp/build.out" <<'PY'
import sys, json
import numpy as np
sys.path.insert(0, "tests/cli")
from fillet_math import hermite_area
r = json.load(open(sys.argv[1]))
(f,) = r["fillets"]
assert f["construction"] == "vbs", f["construction"]
assert f["cells"] == ["fillet.1.1", "fillet.1.2", "fillet.1.3"], f["cells"]
assert max(f["gap"]) < 1e-12 and f["blend_gap"] < 1e-12, (f["gap"], f["blend_gap"])
assert max(f["g1_angle"]) < 1e-6, f["g1_angle"]
assert f["glue"] == 0.0, f["glue"]
assert f["jacobian"] == "positive" and len(f["cell_jacobian"]) == 3, f
assert all(lo > 0 for lo, hi in f["cell_jacobian"]), f["cell_jacobian"]
assert len(f["cell_shapes"]) == 3
# Eq. 8's jump on C: red floor, blue wall, |g_1 - g_2| = 1; T_1 carries the mean on C, half a jump off.
assert abs(f["vbs"]["c_property_jump"] - 1) < 1e-12, f["vbs"]
assert abs(max(f["property_jump"]) - 0.5) < 1e-12, f["property_jump"]
cells = {c["name"]: c for c in r["cells"]}
for i, name in enumerate(f["cells"]):
    c = cells[name]
    assert c["verdict"] == "fillet" and c["min_jacobian"] == f["cell_jacobian"][i][0], c
d1, d2, tau, length = 1.0, 0.5, 1.2, 4.0
exact = hermite_area(d1, d2, tau) * length  # tests/cli/fillet_math.py
vol = sum(cells[n]["volume"] for n in f["cells"])
assert abs(vol - exact) < 1e-9 * exact, (vol, exact)
assert r["valid"]
print("vbs hermite corner: volume", vol, "exact", exact)
PY
"$trivox" build "$tmp/corner.json" -o "$tmp/hermite2.json" > "$tmp/human.out"
grep -q "fillet.1 .*fillet.1.1,fillet.1.2,fillet.1.3 .*floor.w1/wall.u1 .*vbs .*positive .*composed" "$tmp/human.out" ||
  { cat "$tmp/human.out"; exit 1; }

# The chamfer with legs 1 (flend, dip 0).
corner '"distance": 1, "section": "flend", "dip": 0, "construction": "vbs"'
"$trivox" build "$tmp/corner.json" -o "$tmp/chamfer.json" --json > "$tmp/build.out"
"$trivox" info "$tmp/chamfer.json" --json > "$tmp/info.out"
for p in 2.1,2,0.1 2.8,2,0.05 2.05,2,0.8 2.5,2,0.45 2.55,2,0.55; do
  "$trivox" locate "$tmp/chamfer.json" --xyz $p --json > "$tmp/loc-$p.out"
done
"$py" - "$tmp/build.out" "$tmp/info.out" "$tmp" <<'PY'
import sys, json, math
r, info, tmp = json.load(open(sys.argv[1])), json.load(open(sys.argv[2])), sys.argv[3]
(f,) = r["fillets"]
assert f["glue"] == 0.0 and all(lo > 0 for lo, hi in f["cell_jacobian"]), f
rr = 1 / (2 + math.sqrt(2))
expected = {"fillet.1.1": 4 * rr * rr, "fillet.1.2": (2 - 4 * rr * rr) / 2, "fillet.1.3": (2 - 4 * rr * rr) / 2}
built = {c["name"]: c["volume"] for c in r["cells"]}
# info integrates det J over the cells' elements (geom::volume); build over their faces.
read = {c["name"]: c["volume"] for c in info["cells"]}
for name, v in expected.items():
    assert abs(built[name] - v) < 1e-12 * v and abs(read[name] - v) < 1e-12 * v, (name, built[name], read[name], v)
# (x - 2, z): (0.1, 0.1) in the square at C; (0.8, 0.05) by the floor's rail; (0.05, 0.8) by the
# wall's; (0.5, 0.45) below the diagonal D_b, in T_2; (0.55, 0.55) beyond the chamfer x - 2 + z = 1.
cell = {"2.1,2,0.1": "fillet.1.1", "2.8,2,0.05": "fillet.1.2", "2.05,2,0.8": "fillet.1.3", "2.5,2,0.45": "fillet.1.2",
        "2.55,2,0.55": None}
for p, name in cell.items():
    loc = json.load(open(f"{tmp}/loc-{p}.out"))
    assert loc["cell"] == name and loc["inside"] == (name is not None), (p, loc)
    if name:
        q = [float(x) for x in p.split(",")]
        assert max(abs(a - b) for a, b in zip(loc["point"], q)) < 1e-6, loc
        # Every sleeve surface carries an affine mix of red and blue, and so do the Boolean sums.
        pr = loc["properties"]
        assert abs(pr["r"] + pr["b"] - 1) < 1e-9 and abs(pr["g"]) < 1e-12, (p, pr)
print("vbs chamfer: T_1", built["fillet.1.1"], "= 4 r^2", expected["fillet.1.1"])
PY

# The shipped models, built with either construction.
for m in fillet_spheres fillet_sphere_cone; do
  for c in ruled vbs; do
    "$py" - "models/$m.json" "$c" > "$tmp/$m-$c.json" <<'PY'
import sys, json
s = json.load(open(sys.argv[1]))
s["operations"][0]["construction"] = sys.argv[2]
json.dump(s, sys.stdout)
PY
    "$trivox" build "$tmp/$m-$c.json" -o "$tmp/$m-$c-model.json" --json > "$tmp/$m-$c.out"
  done
  "$py" - "$tmp/$m-ruled.out" "$tmp/$m-vbs.out" "$tmp/$m-ruled-model.json" "$tmp/$m-vbs-model.json" <<'PY'
import sys, json
import numpy as np
rr, rv = json.load(open(sys.argv[1])), json.load(open(sys.argv[2]))
(fr,), (fv,) = rr["fillets"], rv["fillets"]
assert fr["construction"] == "ruled" and fr["cells"] == ["fillet.1a", "fillet.1b"], fr["cells"]
assert fv["construction"] == "vbs" and fv["cells"] == ["fillet.1.1", "fillet.1.2", "fillet.1.3"], fv["cells"]
for f in (fr, fv):
    assert f["jacobian"] == "positive" and all(lo > 0 for lo, hi in f["cell_jacobian"]), f["cell_jacobian"]
    assert max(f["gap"]) < 1e-5 and f["blend_gap"] < 1e-12 and max(f["g1_angle"]) < 1e-5, f
assert fv["glue"] == 0.0, fv["glue"]
assert rr["valid"] and rv["valid"]
# Both solids have the same faces on S^_1, S^_2 and S_b (one join at C), so they differ only by
# their caps u = 0 and u = 1, which on the closed C lie within delta of each other (delta: the
# largest distance between a cell's first and last control-point layers along u; the caps are
# within it by the convex hull property). Each solid is the closed one plus the sliver between its
# caps, at most delta times the section's area A: |V_vbs - V_ruled| <= 2 delta A. A is taken as
# V / L (L: C's control polygon, >= its length) with a factor 4 for the section's variation.
def cells(path):
    out = {}
    for c in json.load(open(path))["cells"]:
        if c["name"].startswith("fillet."):
            t = c["trivariate"]
            n = [len(k) - o for k, o in zip(t["knots"], t["orders"])]
            out[c["name"]] = np.array(t["points"]).reshape(n[2], n[1], n[0], -1)[..., :3]
    return out
cr, cv = cells(sys.argv[3]), cells(sys.argv[4])
delta = max(np.linalg.norm(P[:, :, 0] - P[:, :, -1], axis=-1).max() for P in list(cr.values()) + list(cv.values()))
C = cv["fillet.1.1"][-1, 0]  # T_1's edge (v, w) = (0, 1) is C
L = np.linalg.norm(np.diff(C, axis=0), axis=1).sum()
vol = {c["name"]: c["volume"] for r in (rr, rv) for c in r["cells"] if c["name"].startswith("fillet.")}
Vr = vol["fillet.1a"] + vol["fillet.1b"]
Vv = vol["fillet.1.1"] + vol["fillet.1.2"] + vol["fillet.1.3"]
tol = 8 * delta * Vr / L + 1e-12 * Vr
assert abs(Vv - Vr) <= tol, (Vv, Vr, tol)
print(sys.argv[4].split("/")[-1], "vbs volume", Vv, "ruled", Vr, "difference", Vv - Vr, "bound", tol, "seam", delta)
PY
done

# Bad values: exit 2 with the pointer and what was expected; nothing written.
corner '"distance": 1, "construction": "vbz"'
expect_fail 'corner.json: /operations/0/construction: unknown construction "vbz"; expected "ruled", "vbs" or "vrep"' \
  "$trivox" build "$tmp/corner.json" -o "$tmp/x.json"
corner '"distance": 1, "construction": 3'
expect_fail 'corner.json: /operations/0/construction: found the number 3; expected "ruled", "vbs" or "vrep"' \
  "$trivox" build "$tmp/corner.json" -o "$tmp/x.json"
corner '"distance": 1, "blend": "shepard", "construction": "vbs"'
expect_fail 'corner.json: /operations/0/construction: "vbs" with "blend": "shepard"; expected "ruled"' \
  "$trivox" build "$tmp/corner.json" -o "$tmp/x.json"
corner '"construction": "vbs", "bridge": true'
expect_fail 'corner.json: /operations/0/construction: "construction" with "bridge": true; expected only' \
  "$trivox" build "$tmp/corner.json" -o "$tmp/x.json"
[ ! -e "$tmp/x.json" ]
# Tangents 2.5 and 3 times the width fold the section: the division folds (the cells' centres
# disagree in sign) or leaves the fillet (C_c projects onto a rail). Exit 1, nothing written.
for t in 2.5:'det J at the cells. centres is' 3:'the projection of C_c(1/2) on S^_1(1/2, v) lands at v = 1'; do
  corner '"distance": [1, 0.5], "tau": '"${t%%:*}"', "construction": "vbs"'
  expect_failed "corner.json: /operations/0: VBS fillet: ${t#*:}" "$tmp/x.json" "$trivox" build "$tmp/corner.json" -o "$tmp/x.json"
done
echo "vbs_fillet: ok"
