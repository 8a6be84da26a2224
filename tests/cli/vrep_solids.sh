#!/usr/bin/env bash
# End-to-end: the V-rep paper's solids (Massarwi & Elber 2016, Sec. 6, Figs. 15-17, Table 1)
# rebuilt as models/vrep_solid_{a,b,c}.json from non-singular primitives and Booleans
# (docs/booleans.md, "The V-rep paper's solids"). The paper gives no dimensions; the scenes
# repeat each figure's construction (Fig. 15: one union, two subtractions; Fig. 16: one
# intersection, two unions, five subtractions; Fig. 17: two unions, three subtractions) and V-cell
# count. Truths:
# - `trivox build` and `trivox info` count 7, 12 and 19 V-cells, none of them empty, every trimmed
#   one measured on its boundary faces (exact), not sampled;
# - inclusion-exclusion, to 1e-8 relative: vol(solid) plus the volumes of the operands' overlaps
#   (built as intersection scenes) equals the operands' volumes (the untrimmed primitives'
#   quadrature, `trivox build` of the scene without operations) less what the subtractions
#   remove, which is analytic where a hole's walls are a primitive's own faces (a box through a
#   plate; a cylinder's section times the length it runs through the solid);
# - the same volume against the exact circles of the dimensions, within 1e-3 relative (the
#   cylinders are polynomial approximations of their circles within 2e-4 of the radius);
# - each solid prints (`trivox slice`, coarse voxels: the voxel volume within 3 percent);
# - `trivox mesh`: Fig. 15's solid gives a closed manifold of genus 2 (a window and a hole); the
#   other two are refused as docs/mesh.md documents (exit 1, nothing written): Fig. 16's trimmed
#   faces do not all meet within the weld distance, Fig. 17's plate face is glued to a post piece
#   over part of its area only; or, where the mesher handles them, closed manifolds of genus 5
#   and 1 with the volume within tolerance x area.
set -euo pipefail
source tests/cli/lib.bash "$@"

# aux SCENE OUT CELLS OPS: a scene with SCENE's header and the named cells (a JSON list), and the
# operations OPS (a JSON list).
aux() {
  "$py" - "$@" <<'PY'
import sys, json
s = json.load(open(sys.argv[1])); names = json.loads(sys.argv[3])
s["cells"] = [c for c in s["cells"] if c["name"] in names]
assert len(s["cells"]) == len(names), names
s["operations"] = json.loads(sys.argv[4])
json.dump(s, open(sys.argv[2], "w"))
PY
}
# vol MODEL: the model's total volume from `trivox info --json`, checked to be measured exactly.
vol() {
  "$trivox" info "$1" --json > "$tmp/vol.json"
  "$py" - "$tmp/vol.json" <<'PY'
import sys, json
r = json.load(open(sys.argv[1]))
for c in r["cells"]:
    assert c.get("volume_method", "boundary") == "boundary", c
print(repr(r["volume"]))
PY
}

for s in a:7 b:12 c:19; do
  IFS=: read -r name cells <<< "$s"
  scene=models/vrep_solid_$name.json
  "$trivox" build "$scene" -o "$tmp/$name.json" --json > "$tmp/$name.build"
  "$trivox" info "$tmp/$name.json" --json > "$tmp/$name.info"
  "$py" - "$tmp/$name.build" "$tmp/$name.info" "$cells" <<'PY'
import sys, json
b = json.load(open(sys.argv[1])); r = json.load(open(sys.argv[2])); n = int(sys.argv[3])
assert b["valid"] and len(b["cells"]) == n, (len(b["cells"]), n)
assert len(r["cells"]) == n and r["topology"]["v_cells"] == n, r["topology"]
for c in r["cells"]:
    # Every V-cell is a real part of the solid, and every piece is measured exactly.
    assert c["volume"] > 1e-4 * r["volume"], c
    if c.get("trimmed"):
        assert c["volume_method"] == "boundary", c
        p = c["piece"]
        assert not p["empty"] and p["closure"] < 1e-9 and p["spread"] < 1e-9, c
for bc, ic in zip(b["cells"], r["cells"]):
    assert bc["name"] == ic["name"] and abs(bc["volume"] - ic["volume"]) <= 1e-12 * r["volume"], (bc, ic)
PY
  # The operands untrimmed: each primitive's quadrature volume.
  aux "$scene" "$tmp/${name}_ops.json" "$("$py" -c 'import json,sys; print(json.dumps([c["name"] for c in json.load(open(sys.argv[1]))["cells"]]))' "$scene")" '[]'
  "$trivox" build "$tmp/${name}_ops.json" -o "$tmp/${name}_ops-model.json" --json > "$tmp/${name}_ops.build"
done

# The overlaps of the operands, as intersection scenes.
overlap() {  # overlap SOLID A B: vol(A n B) of SOLID's primitives A and B
  aux "models/vrep_solid_$1.json" "$tmp/ov.json" "[\"$2\", \"$3\"]" "[{\"op\": \"intersection\", \"a\": \"$2\", \"b\": \"$3\"}]"
  "$trivox" build "$tmp/ov.json" -o "$tmp/ov-model.json" --force > /dev/null
  vol "$tmp/ov-model.json"
}
a_disk_bar=$(overlap a disk bar)
b_cam_clip=$(overlap b cam clip)
b_cam_plate=$(overlap b cam plate)
b_cam_tab=$(overlap b cam tab)
c_boss_plate=$(overlap c boss plate)
c_post_plate=$(overlap c post plate)
c_boss_keyway=$(overlap c boss keyway)

"$py" - "$tmp" "$a_disk_bar" "$b_cam_clip" "$b_cam_plate" "$b_cam_tab" "$c_boss_plate" "$c_post_plate" "$c_boss_keyway" <<'PY'
import sys, json, math
tmp = sys.argv[1]
a_disk_bar, b_cam_clip, b_cam_plate, b_cam_tab, c_boss_plate, c_post_plate, c_boss_keyway = map(float, sys.argv[2:9])
def prims(name):  # each primitive's quadrature volume, untrimmed
    return {p["name"]: p["volume"] for p in json.load(open(f"{tmp}/{name}_ops.build"))["primitives"]}
def volume(name):
    return json.load(open(f"{tmp}/{name}.info"))["volume"]
def check(what, got, want, rel):
    err = abs(got - want) / abs(want)
    print(f"{what}: {got!r} against {want!r}, relative {err:.2g}")
    assert err <= rel, (what, got, want, err)
pi, sqrt, acos, asin = math.pi, math.sqrt, math.acos, math.asin
def seg(d, r):  # area of the circle of radius r beyond a chord at distance d from its centre
    return r * r * acos(d / r) - d * sqrt(r * r - d * d)
def strip(x0, x1, r, h):  # area between the chord height h and the circle's upper arc, x in [x0, x1]
    F = lambda x: x / 2 * sqrt(r * r - x * x) + r * r / 2 * asin(x / r)
    return F(x1) - F(x0) - h * (x1 - x0)

# Fig. 15: ((disk u bar) - window) - hole. The window (12 x 4, through the bar's 4) and the hole
# (its section, over the disk's height 6) lie wholly in one operand each.
p = prims("a")
check("a: inclusion-exclusion", volume("a") + a_disk_bar, p["disk"] + p["bar"] - 12 * 4 * 4 - p["hole"] / 8 * 6, 1e-8)
check("a: the exact circles", volume("a"),
      pi * 100 * 6 + 32 * 8 * 4 - 4 * strip(-4, 4, 10, 8) - 12 * 4 * 4 - pi * 9 * 6, 1e-3)

# Fig. 16: (((cam n clip) u plate) u tab) - bore - 4 square holes. The cam's parts in the plate
# and in the tab lie within the clip; the bore (inside the cam's core) runs through the cam's 12.
p = prims("b")
check("b: inclusion-exclusion", volume("b") + b_cam_plate + b_cam_tab,
      b_cam_clip + p["plate"] + p["tab"] - p["bore"] / 17 * 12 - 4 * 4 * 4 * 6, 1e-8)
cam_clip = 12 * (pi * 144 - 2 * seg(10.2, 12))
check("b: the exact circles", volume("b"),
      cam_clip + 60 * 40 * 6 + 1.6 * 8 * 6.6 - 12 * seg(7.2, 12) - 8 * strip(-8.8, -7.2, 12, 6.6) - 12 * pi * 16 - 384, 1e-3)

# Fig. 17: ((boss u plate) u post) - bore - keyway - socket. The bore runs through the boss's 20,
# the socket through the post from 10 sqrt(1.04) along its axis to the top at 24.
p = prims("c")
socket = 24 - 10 * sqrt(1.04)
check("c: inclusion-exclusion", volume("c") + c_boss_plate + c_post_plate + c_boss_keyway,
      p["boss"] + p["plate"] + p["post"] - p["bore"] / 30 * 20 - p["socket"] / 16 * socket, 1e-8)
check("c: the exact circles", volume("c"),
      pi * 196 * 20 + 80 * 40 * 8 + pi * 25 * 24 - 20 * seg(8.4, 14) - pi * 25 * 5 * sqrt(1.04)
      - 20 * strip(-2, 2, 14, 11.2) - 20 * pi * 36 - pi * 2.25 * socket, 1e-3)
PY

# Each prints: coarse voxels (1/51 inch, 1 mm layers), the voxel volume within 3 percent.
for name in a b c; do
  "$trivox" slice "$tmp/$name.json" -o "$tmp/$name-stack" --dpi 51,51 --layer 1 --progress never > /dev/null
  [ -f "$tmp/$name-stack/ConfigFile.xml" ]
  "$trivox" inspect "$tmp/$name-stack" --json > "$tmp/$name.inspect"
  "$py" - "$tmp/$name.inspect" "$tmp/$name.info" <<'PY'
import sys, json
r = json.load(open(sys.argv[1])); v = json.load(open(sys.argv[2]))["volume"]
got = sum(m["volume_mm3"] for m in r["materials"])
assert abs(got - v) < 0.03 * v, (got, v)
PY
done

# Meshes. Fig. 15's solid: one closed shell of genus 2, its volume within tolerance x area.
"$trivox" mesh "$tmp/a.json" -o "$tmp/a.stl" --json > "$tmp/a.mesh"
"$py" - "$tmp/a.mesh" "$tmp/a.info" <<'PY'
import sys, json
m = json.load(open(sys.argv[1])); v = json.load(open(sys.argv[2]))["volume"]
assert m["trimmed"] and m["manifold"] and m["shells"] == 1 and m["euler"] == -2, m
assert abs(m["cell_volume"] - v) <= 1e-9 * v, (m["cell_volume"], v)
assert abs(m["volume"] - v) <= m["tolerance"] * m["area"], (m["volume"], v)
PY
# Figs. 16 and 17: refused as docs/mesh.md documents (exit 1, nothing written), or, once the
# mesher handles them, meshed closed: one shell of genus 5 (the bore and four holes) and of genus 1
# (the bore; the keyway and the socket are blind), the volume within tolerance x area.
# mesh_or_refusal NAME EULER PATTERN
mesh_or_refusal() {
  set +e
  "$trivox" mesh "$tmp/$1.json" -o "$tmp/$1.stl" --json > "$tmp/$1.mesh" 2> "$tmp/$1.mesh_err"
  local rc=$?
  set -e
  if [ $rc -eq 1 ]; then
    grep -q -- "$3" "$tmp/$1.mesh_err" || { echo "$1: refusal lacks '$3'"; cat "$tmp/$1.mesh_err"; exit 1; }
    [ ! -e "$tmp/$1.stl" ] || { echo "$1: mesh written after the refusal"; exit 1; }
    echo "$1: mesh refused: $(cut -c1-160 "$tmp/$1.mesh_err")"
  elif [ $rc -eq 0 ]; then
    "$py" - "$tmp/$1.mesh" "$tmp/$1.info" "$2" <<'PY'
import sys, json
m = json.load(open(sys.argv[1])); v = json.load(open(sys.argv[2]))["volume"]
assert m["trimmed"] and m["manifold"] and m["shells"] == 1 and m["euler"] == int(sys.argv[3]), m
assert abs(m["cell_volume"] - v) <= 1e-9 * v, (m["cell_volume"], v)
assert abs(m["volume"] - v) <= m["tolerance"] * m["area"], (m["volume"], v)
PY
    echo "$1: meshed, one closed shell"
  else
    echo "$1: trivox mesh exited $rc"; cat "$tmp/$1.mesh_err"; exit 1
  fi
}
mesh_or_refusal b -8 "the boundary mesh is not a closed manifold: .* boundary edges"
mesh_or_refusal c 0 'is glued to cell "post\.[a-z0-9]*" ([0-9]*) over part of its area only'
echo "vrep_solids: all checks passed"
