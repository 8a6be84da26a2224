#!/usr/bin/env bash
# End-to-end: Booleans in scenes (`trivox build` with union / intersection / subtraction; Massarwi &
# Elber 2016 Sec. 4). Truths: a ball of radius 10 less the half-space box x >= 0 is a half ball,
# 2/3 pi 10^3 = 2094.395 mm^3 (info's sampled volume and the printed voxel count agree within
# 1 percent); locate says inside / outside by the sign of x; the union of two boxes of Massarwi &
# Elber 2016 Fig. 3 has its topology counts (3 cells, 16 V-surfaces, 18 half-V-surfaces, 28
# V-curves, 16 V-points) and a voxel count equal to its 3 unit-cube volume; where two inputs overlap
# a sum_clip blend gives the sum of their values; bad operands exit 2 naming the place.
set -euo pipefail
source tests/cli/lib.bash "$@"

cat > "$tmp/half.json" <<'EOF'
{ "trivox": 1, "units": "mm", "properties": ["r"],
  "cells": [
    { "name": "ball", "primitive": {"type": "sphere", "center": [0, 0, 0], "radius": 10}, "field": {"constant": [0.2]} },
    { "name": "cut", "primitive": {"type": "box", "min": [0, -20, -20], "max": [20, 20, 20]}, "field": {"constant": [0.6]} }
  ],
  "operations": [ {"op": "subtraction", "a": "ball", "b": "cut", "name": "half"} ] }
EOF
"$trivox" build "$tmp/half.json" -o "$tmp/half-model.json" --json > "$tmp/build.out"
"$trivox" info "$tmp/half-model.json" --json > "$tmp/info.out"
"$py" - "$tmp/info.out" <<'PY'
import sys, json, math
r = json.load(open(sys.argv[1]))
exact = 2.0 / 3.0 * math.pi * 1000
assert len(r["cells"]) == 7, [c["name"] for c in r["cells"]]
# ball.x0 lies wholly on the kept side (its box misses the cut: a plain cell); the others are
# trimmed, ball.x1 (wholly inside the cut) down to nothing.
assert [c["name"] for c in r["cells"] if not c.get("trimmed")] == ["ball.x0"], r["cells"]
assert abs(next(c["volume"] for c in r["cells"] if c["name"] == "ball.x1")) < 1e-12
assert abs(r["volume"] - exact) < 0.01 * exact, (r["volume"], exact)
PY
"$trivox" locate "$tmp/half-model.json" --xyz -5,1,2 --json > "$tmp/in.out"
"$trivox" locate "$tmp/half-model.json" --xyz 5,1,2 --json > "$tmp/out.out"
"$py" -c "
import json
a = json.load(open('$tmp/in.out')); b = json.load(open('$tmp/out.out'))
assert a['inside'] and a['cell'].startswith('ball.') and abs(a['properties']['r'] - 0.2) < 1e-9, a
assert not b['inside'], b"
# The print: voxels x voxel volume = the half ball within 1 percent.
"$trivox" slice "$tmp/half-model.json" -o "$tmp/half-stack" --dpi 127,127 --layer 0.2 --progress never --json > "$tmp/slice.out"
"$trivox" inspect "$tmp/half-stack" --json > "$tmp/inspect.out"
"$py" - "$tmp/inspect.out" <<'PY'
import sys, json, math
r = json.load(open(sys.argv[1]))
exact = 2.0 / 3.0 * math.pi * 1000
v = sum(m["volume_mm3"] for m in r["materials"])
assert abs(v - exact) < 0.01 * exact, (v, exact)
PY

# Massarwi & Elber 2016, Fig. 3 and a sum_clip blend.
cat > "$tmp/fig3.json" <<'EOF'
{ "trivox": 1, "units": "mm", "properties": ["r"],
  "cells": [
    { "name": "O1", "primitive": {"type": "box", "min": [0, 0, 0], "max": [2, 1, 1]}, "field": {"constant": [0.25]} },
    { "name": "O2", "primitive": {"type": "box", "min": [1, 0, 0], "max": [2, 1, 2]}, "field": {"constant": [0.5]} }
  ],
  "operations": [ {"op": "union", "a": "O1", "b": "O2", "blend": "sum_clip"} ] }
EOF
"$trivox" build "$tmp/fig3.json" -o "$tmp/fig3-model.json" > /dev/null
"$trivox" info "$tmp/fig3-model.json" --json > "$tmp/fig3.out"
"$py" - "$tmp/fig3.out" <<'PY'
import sys, json
r = json.load(open(sys.argv[1]))
t = r["topology"]
assert (t["v_cells"], t["v_surfaces"], t["half_v_surfaces"], t["v_curves"], t["v_points"]) == (3, 16, 18, 28, 16), t
assert abs(r["volume"] - 3) < 1e-9, r["volume"]
PY
"$trivox" locate "$tmp/fig3-model.json" --xyz 1.5,0.5,0.5 --json > "$tmp/both.out"
"$py" -c "
import json
a = json.load(open('$tmp/both.out'))
assert a['inside'] and abs(a['properties']['r'] - 0.75) < 1e-9, a"
# 0.1 mm voxels, centres off every face: exactly 3 / 0.001 voxels.
"$trivox" slice "$tmp/fig3-model.json" -o "$tmp/fig3-stack" --dpi 254,254 --layer 0.1 --progress never > /dev/null
"$trivox" inspect "$tmp/fig3-stack" --json > "$tmp/fig3-inspect.out"
"$py" - "$tmp/fig3-inspect.out" <<'PY'
import sys, json
r = json.load(open(sys.argv[1]))
n = sum(m["voxels"] for m in r["materials"])
assert n == 3000, n
PY

# Bad operations.
cat > "$tmp/bad.json" <<'EOF'
{ "trivox": 1, "units": "mm", "properties": [],
  "cells": [ { "name": "O1", "primitive": {"type": "box", "min": [0, 0, 0], "max": [2, 1, 1]} } ],
  "operations": [ {"op": "union", "a": "O1", "b": "nothing"} ] }
EOF
expect_fail '/operations/0/b: no cell or result named "nothing"' "$trivox" build "$tmp/bad.json" -o "$tmp/bad-model.json"
sed 's/"b": "nothing"/"b": "O1", "blend": "pizza"/' "$tmp/bad.json" > "$tmp/bad2.json"
expect_fail '/operations/0/blend: unknown blend rule "pizza"' "$trivox" build "$tmp/bad2.json" -o "$tmp/bad-model.json"
[ ! -e "$tmp/bad-model.json" ]
echo "booleans: all checks passed"
