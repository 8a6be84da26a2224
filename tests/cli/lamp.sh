#!/usr/bin/env bash
# End-to-end: the lamp of Masalha et al. 2021, Fig. 15 (models/lamp.json): a base disk, a rod and a
# spherical head (cylinder, cylinder and sphere primitives, each with its own rgb field),
# filleted base-rod and rod-head with fitted fillets (Sec. 4.3: the faces are B-splines) and the
# Shepard blend (Sec. 7.2). The rod's side is four cells, so each junction is four fillets, one
# per face pair (Sec. 6 for faces joined G1: nothing to bridge). Checks, from the geometry alone:
# - every cell is valid, each of the 8 fillets is fitted with det J > 0, G1 at the rails;
# - no gap between the four fillets of a junction: points in the corner between the faces
#   (0.4 mm from each) at angles through and between the seams of the rod's cells (45 degrees
#   apart) are inside a fillet cell of that junction; points beyond the rails' corner are not;
# - the exact Shepard blend next to the base's top face equals the base's linear field there.
set -euo pipefail
source tests/cli/lib.bash "$@"

"$trivox" build models/lamp.json -o "$tmp/lamp.model.json" --json > "$tmp/build.json"
"$py" - "$tmp/build.json" "$tmp/lamp.model.json" <<'PY'
import sys, json
b = json.load(open(sys.argv[1]))
assert b["valid"] is True, "a cell is invalid"
f = b["fillets"]
assert len(f) == 8, len(f)
for x in f:
    assert x["jacobian"] == "positive", (x["name"], x["jacobian"])
    assert x["composed"] == [False, False], (x["name"], x["composed"])  # fitted (Sec. 4.3)
    assert max(x["gap"]) < 1e-5 and max(x["g1_angle"]) < 1e-4, (x["name"], x["gap"], x["g1_angle"])
m = json.load(open(sys.argv[2]))
shep = [c["name"] for c in m["cells"] if "shepard" in c]
assert len(shep) == 16, shep
print("lamp: 8 fitted fillets, 16 Shepard cells, every cell valid")
PY

# locate CELL-PREFIX X Y Z: the point lies in a cell whose name starts with CELL-PREFIX ("-": void).
locate_in() {
  local want=$1 xyz=$2
  local cell
  cell=$("$trivox" locate "$tmp/lamp.model.json" --xyz "$xyz" --json | "$py" -c 'import sys, json; d = json.load(sys.stdin); print(d["cell"] if d["inside"] else "-")')
  case $cell in
    $want*) ;;
    *) echo "point $xyz: in '$cell', expected '$want'"; exit 1 ;;
  esac
}
polar() {  # polar R Y DEG: the point at radius R from the rod's axis (y), height Y, angle DEG
  "$py" -c "import math, sys; r, y, a = map(float, sys.argv[1:]); a = math.radians(a); print(f'{r * math.cos(a):.9f},{y:.9f},{r * math.sin(a):.9f}')" "$@"
}
# The base's top face is y = 14 and the rod's radius 5: the corner C is the circle r = 5, y = 14.
# The head's sphere (centre y = 190, radius 22) meets the rod at y = 190 - sqrt(22^2 - 5^2).
c_head=$("$py" -c 'import math; print(190 - math.sqrt(22**2 - 5**2))')
for deg in 0 22.5 45 67.5 90 135 180 225 270 315; do
  locate_in base_rod_ "$(polar 5.4 14.4 "$deg")"
  # 0.4 mm out from the rod plus 0.4 mm out of the sphere along its normal at C.
  xyz=$("$py" -c "
import math, sys
a = math.radians(float(sys.argv[1])); yc = float(sys.argv[2])
r, y = 5.0, yc
n = (r / 22.0, (y - 190.0) / 22.0)  # outward normal of the sphere at C, in the (r, y) plane
r, y = r + 0.4 + 0.4 * n[0], y + 0.4 * n[1]
print(f'{r * math.cos(a):.9f},{y:.9f},{r * math.sin(a):.9f}')" "$deg" "$c_head")
  locate_in rod_head_ "$xyz"
done
for deg in 0 45 100 200; do
  locate_in - "$(polar 7.9 16.9 "$deg")"  # beyond the blend, near the corner of the rails (8, 17)
done

# The Shepard blend reproduces g_1 on S^_1 (Sec. 7.2): 0.001 above the base's top face, at
# r = 7 (inside the fillet, which reaches r = 8 there), it equals the base's linear field
# (r, g, b) = (0.15, 0.2, 0.55) + (x + 32) / 64 * (0.2, -0.1, -0.25) to well below 1/512.
for deg in 0 120; do
  xyz=$(polar 7 14.001 "$deg")
  "$trivox" locate "$tmp/lamp.model.json" --xyz "$xyz" --blend shepard --json > "$tmp/loc.json"
  "$py" - "$tmp/loc.json" "$xyz" <<'PY'
import sys, json
d = json.load(open(sys.argv[1]))
x = float(sys.argv[2].split(",")[0])
assert d["inside"] and d["cell"].startswith("base_rod_"), d["cell"]
s = (x + 32) / 64
want = (0.15 + 0.2 * s, 0.2 - 0.1 * s, 0.55 - 0.25 * s)
got = [d["properties"][k] for k in ("r", "g", "b")]
err = max(abs(a - b) for a, b in zip(got, want))
assert err < 1e-4, (got, want, err)
print(f"Shepard next to the base at x = {x:.4f}: {got} vs {want} (error {err:.2e})")
PY
done
echo "lamp: ok"
