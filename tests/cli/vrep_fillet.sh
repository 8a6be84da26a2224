#!/usr/bin/env bash
# End-to-end: the scene fillet with "construction": "vrep" (Masalha et al. 2021, Sec. 5, Def. 5.1,
# Alg. 6: the half volumetric Boolean sum trimmed by S^_1, S^_2, S_b and the caps) built by `trivox
# build`, read back by `trivox locate` and sliced by `trivox slice`. Truths:
# - between a floor z <= 0 and a wall x <= 2 (boxes), the trimmed cell is the region between the
#   faces and the Hermite section: 4 times its area by Green's theorem (numpy), the ruled
#   fillet's volume; its faces lie on S^_1, S^_2, S_b (gap 0), G1 at the rails, det J of T_hbs
#   the constant d1 d2 |C'| (Def. 5.1 of two perpendicular strips);
# - the slices of the V-rep and ruled models agree voxel for voxel except within one voxel of the
#   boundary (each differing voxel has, in both stacks, a neighbour of the other kind), and the
#   fillet's voxels (the stack minus the one without the fillet) count its volume to within the
#   boundary's area times half a voxel diagonal;
# - the same on the shipped fillet_spheres model (closed C, no caps): volumes within the seam's
#   bound, slices within one voxel of the boundary;
# - bad values exit 2 naming the JSON pointer.
set -euo pipefail
source "$(dirname "$0")/lib.bash" "$@"

corner() { corner_scene "$@"; }  # corner FILE FILLET-OPS
op() { fillet_op "$1"; }
slice() { "$trivox" slice "$1" -o "$2" --dpi 300,300 --layer 0.1 --progress never --force --json > "$2.json"; }

# The Hermite corner, tau 1.2, d = (1.5, 1.2), built three ways: V-rep, ruled, no fillet.
corner "$tmp/vrep.json" "$(op '"distance": [1.5, 1.2], "tau": 1.2, "construction": "vrep"')"
corner "$tmp/ruled.json" "$(op '"distance": [1.5, 1.2], "tau": 1.2, "construction": "ruled"')"
corner "$tmp/none.json" ""
for c in vrep ruled none; do "$trivox" build "$tmp/$c.json" -o "$tmp/$c-model.json" --json > "$tmp/$c.out"; done
"$trivox" build "$tmp/vrep.json" -o "$tmp/vrep-model2.json" > "$tmp/human.out"
grep -q "fillet.1 .*fillet.1 .*floor.w1/wall.u1 .*vrep .*positive .*composed" "$tmp/human.out" || { cat "$tmp/human.out"; exit 1; }
grep -q "fillet.1 (vrep): T_hbs 7.2 - beyond S_b" "$tmp/human.out" || { cat "$tmp/human.out"; exit 1; }
# (x - 2, z): (0.1, 0.1) at C inside the fillet; (1.3, 1.0) in T_hbs's box [0, 1.5] x [0, 1.2] but
# beyond the section (trimmed away); (0.3, 0.3) inside (the section passes (0.51, 0.36) at its middle).
for p in 2.1,2,0.1 3.3,2,1.0 2.3,2,0.3; do
  "$trivox" locate "$tmp/vrep-model.json" --xyz $p --json > "$tmp/loc-$p.out"
done
"$py" - "$tmp" <<'PY'
import sys, json
import numpy as np
sys.path.insert(0, "tests/cli")
from fillet_math import hermite_area, hermite_length
tmp = sys.argv[1]
r, rr = json.load(open(f"{tmp}/vrep.out")), json.load(open(f"{tmp}/ruled.out"))
(f,), (fr,) = r["fillets"], rr["fillets"]
assert f["construction"] == "vrep" and f["cells"] == ["fillet.1"], (f["construction"], f["cells"])
assert max(f["gap"]) < 1e-12 and f["blend_gap"] < 1e-12, (f["gap"], f["blend_gap"])
assert max(f["g1_angle"]) < 1e-6 and f["glue"] < 1e-12, f
d1, d2, tau, length = 1.5, 1.2, 1.2, 4.0
# T_hbs(u, v, w) = (2 + d1 v, 4u, d2 w) up to orientation: det J = 4 d1 d2 everywhere.
assert f["jacobian"] == "positive", f["jacobian"]
lo, hi = f["cell_jacobian"][0]
assert abs(lo - 4 * d1 * d2) < 1e-9 and abs(hi - 4 * d1 * d2) < 1e-9, f["cell_jacobian"]
v = f["vrep"]
assert not v["closed"] and v["outside"] < 1e-12 and v["cap_gap"] < 1e-12, v
assert abs(v["hbs_volume"] - d1 * d2 * length) < 1e-12, v["hbs_volume"]
assert abs(v["c_property_jump"] - 1) < 1e-12 and abs(max(f["property_jump"]) - 0.5) < 1e-12, (v, f["property_jump"])
area = hermite_area(d1, d2, tau)  # tests/cli/fillet_math.py
exact = area * length
cells = {c["name"]: c for c in r["cells"]}
vol = cells["fillet.1"]["volume"]
ruled = sum(c["volume"] for c in rr["cells"] if c["name"].startswith("fillet."))
assert abs(vol - exact) < 1e-9 * exact and abs(vol - ruled) < 1e-9 * exact, (vol, exact, ruled)
assert cells["fillet.1"]["verdict"] == "fillet" and r["valid"], cells["fillet.1"]
# The model file: one trimmed cell, the solid beyond S_b as its "without", the caps' curves.
m = json.load(open(f"{tmp}/vrep-model.json"))
(cell,) = [c for c in m["cells"] if c["name"] == "fillet.1"]
assert [c["name"] for c in cell["without"][0]] == ["fillet.1.beyond.1", "fillet.1.beyond.2"], cell.keys()
loc = {p: json.load(open(f"{tmp}/loc-{p}.out")) for p in ["2.1,2,0.1", "3.3,2,1.0", "2.3,2,0.3"]}
assert loc["2.1,2,0.1"]["inside"] and loc["2.1,2,0.1"]["cell"] == "fillet.1", loc["2.1,2,0.1"]
assert not loc["3.3,2,1.0"]["inside"], loc["3.3,2,1.0"]
assert loc["2.3,2,0.3"]["inside"] and loc["2.3,2,0.3"]["cell"] == "fillet.1", loc["2.3,2,0.3"]
# Section length (for the slice test's bound): the Hermite arc, by Gauss on |P'|.
arc = hermite_length(d1, d2, tau)
json.dump({"volume": exact, "area": 2 * area + length * (d1 + d2 + arc)}, open(f"{tmp}/truth.json", "w"))
print(f"vrep corner: volume {vol:.15g}, Green {exact:.15g}, ruled {ruled:.15g}; T_hbs {v['hbs_volume']:.15g}, "
      f"beyond {v['beyond_volume']}")
PY

# Slices of the three models on the same grid (the floor and wall fix the bounds).
for c in vrep ruled none; do slice "$tmp/$c-model.json" "$tmp/s-$c"; done
cat > "$tmp/compare.py" <<'PY'
# compare.py VREP RULED NONE TRUTH: the fillet's voxels in the V-rep and ruled stacks.
import sys, os, glob, json
import numpy as np
import OpenImageIO as oiio

def stack(d):
    out = []
    layer = lambda p: int(os.path.basename(p)[len("slice_"):-len(".png")])
    for path in sorted(glob.glob(os.path.join(d, "slice_*.png")), key=layer):
        inp = oiio.ImageInput.open(path)
        px = inp.read_image(format="uint8")
        inp.close()
        out.append(px[..., 3] > 0)
    return np.array(out)

def boundary(s):
    """Voxels with a 26-neighbour of the other kind (the stack's edge counts as its own kind)."""
    p = np.pad(s, 1, mode="edge")
    b = np.zeros_like(s)
    for dz in (-1, 0, 1):
        for dy in (-1, 0, 1):
            for dx in (-1, 0, 1):
                b |= p[1 + dz:1 + dz + s.shape[0], 1 + dy:1 + dy + s.shape[1], 1 + dx:1 + dx + s.shape[2]] != s
    return b

vrep, ruled, none = (stack(d) for d in sys.argv[1:4])
truth = json.load(open(sys.argv[4]))
summary = json.load(open(sys.argv[1] + ".json"))
pitch = summary["grid"]["pitch"]
assert vrep.shape == ruled.shape == none.shape, (vrep.shape, ruled.shape, none.shape)
assert not (none & ~vrep).any() and not (none & ~ruled).any()  # the filleted cells are unchanged
fv, fr = vrep & ~none, ruled & ~none
diff = vrep != ruled
far = diff & ~(boundary(vrep) & boundary(ruled))
# Counting voxel centres misjudges only voxels the boundary passes through within half a
# diagonal of the centre: |count * voxel - V| <= area * half diagonal.
voxel = pitch[0] * pitch[1] * pitch[2]
half_diag = 0.5 * float(np.linalg.norm(pitch))
bound = truth["area"] * half_diag
for name, f in (("vrep", fv), ("ruled", fr)):
    err = abs(f.sum() * voxel - truth["volume"])
    assert err <= bound, (name, f.sum() * voxel, truth["volume"], bound)
assert fv.sum() > 100, fv.sum()
assert far.sum() == 0, far.sum()
print(f"{sys.argv[1].split('/')[-1]}: fillet voxels vrep {fv.sum()}, ruled {fr.sum()} (volume {truth['volume']:.6g} = "
      f"{truth['volume'] / voxel:.1f} voxels, bound {bound / voxel:.0f}); differing {diff.sum()}, "
      f"of them off the boundary {far.sum()}")
PY
"$py" "$tmp/compare.py" "$tmp/s-vrep" "$tmp/s-ruled" "$tmp/s-none" "$tmp/truth.json"

# The shipped fillet_spheres (closed C, composed sub-regions) built both ways and sliced coarsely.
for c in vrep ruled; do
  "$py" - models/fillet_spheres.json "$c" > "$tmp/sph-$c.json" <<'PY'
import sys, json
s = json.load(open(sys.argv[1]))
s["operations"][0]["construction"] = sys.argv[2]
json.dump(s, sys.stdout)
PY
  "$trivox" build "$tmp/sph-$c.json" -o "$tmp/sph-$c-model.json" --json > "$tmp/sph-$c.out"
done
"$py" - "$tmp" <<'PY'
import sys, json
import numpy as np
tmp = sys.argv[1]
rv, rr = json.load(open(f"{tmp}/sph-vrep.out")), json.load(open(f"{tmp}/sph-ruled.out"))
(fv,), (fr,) = rv["fillets"], rr["fillets"]
assert fv["cells"] == ["fillet.1"] and fv["jacobian"] == "positive", fv
v = fv["vrep"]
assert v["closed"] and v["outside"] < 1e-9, v
assert max(fv["gap"]) < 1e-5 and fv["blend_gap"] < 1e-12 and max(fv["g1_angle"]) < 1e-5, fv
# Both regions have the same S^_1, S^_2, S_b and differ only at the seam of the closed C, where
# each construction's end sections (u = 0, u = 1) lie within delta of each other (the largest
# distance between first and last control-point layers along u of every cell, the trimming
# solid's included). Each volume is the closed region's plus at most delta times the section's
# area A; A <= 4 V / L as in vbs_fillet.sh (L: C's control polygon).
def layers(path):
    out = []
    def walk(c):
        t = c["trivariate"]
        n = [len(k) - o for k, o in zip(t["knots"], t["orders"])]
        out.append(np.array(t["points"]).reshape(n[2], n[1], n[0], -1)[..., :3])
        for solid in c.get("without", []):
            for d in solid:
                walk(d)
    for c in json.load(open(path))["cells"]:
        if c["name"].startswith("fillet."):
            walk(c)
    return out
cells = layers(f"{tmp}/sph-vrep-model.json") + layers(f"{tmp}/sph-ruled-model.json")
delta = max(np.linalg.norm(P[:, :, 0] - P[:, :, -1], axis=-1).max() for P in cells)
T = cells[0]  # T_hbs: its edge (v, w) = (0, 0) is C
C = T[0, 0]
L = np.linalg.norm(np.diff(C, axis=0), axis=1).sum()
vol_v = next(c["volume"] for c in rv["cells"] if c["name"] == "fillet.1")
vol_r = sum(c["volume"] for c in rr["cells"] if c["name"].startswith("fillet."))
tol = 8 * delta * vol_r / L + 1e-12 * vol_r
assert abs(vol_v - vol_r) <= tol, (vol_v, vol_r, tol)
json.dump({"volume": vol_r, "area": 0.0}, open(f"{tmp}/sph-truth.json", "w"))
print(f"fillet_spheres: vrep volume {vol_v:.10g}, ruled {vol_r:.10g}, difference {vol_v - vol_r:.3g}, bound {tol:.3g}")
PY
"$py" - "$tmp/sph-ruled-model.json" > "$tmp/sph-none-model.json" <<'PY'
import sys, json
m = json.load(open(sys.argv[1]))
m["cells"] = [c for c in m["cells"] if not c["name"].startswith("fillet.")]
json.dump(m, sys.stdout)
PY
for c in vrep ruled none; do
  "$trivox" slice "$tmp/sph-$c-model.json" -o "$tmp/ss-$c" --dpi 150,150 --layer 0.2 --progress never --json > "$tmp/ss-$c.json"
done
"$py" - "$tmp" <<'PY'
import sys, json
import numpy as np
tmp = sys.argv[1]
t = json.load(open(f"{tmp}/sph-truth.json"))
# The fillet's boundary area for the count's bound: S^_1, S^_2 and S_b are strips along C of
# widths about d1, d2 and the section's length (at most d1 + d2: a convex section inside the legs'
# parallelogram), so area <= 2 (d1 + d2) L, with d_i the largest distance between the control
# points of C and rail i and L the longest control polygon of C, the rails and K (T_hbs's edges).
m = json.load(open(f"{tmp}/sph-vrep-model.json"))
(c,) = [c for c in m["cells"] if c["name"] == "fillet.1"]
tv = c["trivariate"]
n = [len(k) - o for k, o in zip(tv["knots"], tv["orders"])]
P = np.array(tv["points"]).reshape(n[2], n[1], n[0], -1)[..., :3]
L = max(np.linalg.norm(np.diff(P[a, b], axis=0), axis=1).sum() for a in (0, -1) for b in (0, -1))
d1 = np.linalg.norm(P[0, -1] - P[0, 0], axis=-1).max()
d2 = np.linalg.norm(P[-1, 0] - P[0, 0], axis=-1).max()
t["area"] = 2 * (d1 + d2) * L
json.dump(t, open(f"{tmp}/sph-truth.json", "w"))
PY
"$py" "$tmp/compare.py" "$tmp/ss-vrep" "$tmp/ss-ruled" "$tmp/ss-none" "$tmp/sph-truth.json"

# Bad values: exit 2 with the pointer and what was expected; nothing written.
corner "$tmp/bad.json" "$(op '"distance": 1, "construction": "vrap"')"
expect_fail 'bad.json: /operations/0/construction: unknown construction "vrap"; expected "ruled", "vbs" or "vrep"' \
  "$trivox" build "$tmp/bad.json" -o "$tmp/x.json"
corner "$tmp/bad.json" "$(op '"distance": 1, "blend": "shepard", "construction": "vrep"')"
expect_fail 'bad.json: /operations/0/construction: "vrep" with "blend": "shepard"; expected "ruled"' \
  "$trivox" build "$tmp/bad.json" -o "$tmp/x.json"
corner "$tmp/bad.json" "$(op '"construction": "vrep", "bridge": true')"
expect_fail 'bad.json: /operations/0/construction: "construction" with "bridge": true; expected only' \
  "$trivox" build "$tmp/bad.json" -o "$tmp/x.json"
[ ! -e "$tmp/x.json" ]
echo "vrep_fillet: ok"
