#!/usr/bin/env bash
# End-to-end: `trivox info` and `trivox eval` on shipped models, JSON read back by Python's json.
# Truths: the G+Smo cube [-1,2]^3 has volume 27 and the Fichera corner 7 (7 unit cubes); the demo
# model's block is 40 x 20 x 10 mm and the arch is 40 mm long, 10 mm wide and 4 mm thick
# (a translational sweep along z: volume 40 * 10 * 4 = 1600); its cells are linear or quadratic,
# so eval's values follow from the control points by hand.
set -euo pipefail
source tests/cli/lib.bash "$@"

"$trivox" --version | grep -Eq '^trivox [0-9]+\.[0-9]+\.[0-9]+$'

"$trivox" info models/gismo/cube.xml --json > "$tmp/cube.json"
"$trivox" info models/gismo/fichera.xml --json > "$tmp/fichera.json"
"$trivox" info models/graded_block.json --json > "$tmp/demo.json"
"$trivox" info models/gismo/teapot.xml --json > "$tmp/teapot.json"
"$py" - "$tmp" <<'PY'
import json, sys, os
d = sys.argv[1]
load = lambda n: json.load(open(os.path.join(d, n)))
cube, fichera, demo, teapot = load("cube.json"), load("fichera.json"), load("demo.json"), load("teapot.json")
assert len(cube["cells"]) == 7 and abs(cube["volume"] - 27) < 1e-12, cube["volume"]
assert cube["bbox"] == [[-1, -1, -1], [2, 2, 2]], cube["bbox"]
assert abs(fichera["volume"] - 7) < 1e-12 and all(abs(c["volume"] - 1) < 1e-12 for c in fichera["cells"])
for c in cube["cells"]:
    assert set(c) >= {"name", "orders", "counts", "bbox", "volume"}, c.keys()
assert demo["properties"] == ["r", "g", "b"]
vols = {c["name"]: c["volume"] for c in demo["cells"]}
assert abs(vols["block"] - 8000) < 1e-9 and abs(vols["arch"] - 1600) < 1e-9, vols
assert demo["topology"]["v_cells"] == 2
assert len(teapot["surfaces"]) == 32 and teapot["cells"] == []
assert all(s["orders"] == [4, 4] for s in teapot["surfaces"])
PY

# eval: the block is trilinear, so at (0.25, 0.5, 1) x = 10, y = 10, z = 10, r = 1, g = 0.225,
# b = 0.3 (linear interpolation of the corner values).
"$trivox" eval models/graded_block.json --cell block --uvw 0.25,0.5,1 --json > "$tmp/eval.json"
"$py" - "$tmp/eval.json" <<'PY'
import json, sys
e = json.load(open(sys.argv[1]))
assert e["point"] == [10.0, 10.0, 10.0], e["point"]
p = e["properties"]
assert list(p) == ["r", "g", "b"]
assert abs(p["r"] - 1) < 1e-15 and abs(p["g"] - 0.225) < 1e-15 and abs(p["b"] - 0.3) < 1e-15, p
PY
"$trivox" eval models/gismo/cube.xml --cell patch0 --uvw 0.5,0.5,0.5 | grep -q "point: (0.5, 0.5, 0.5)"

# Bad input: exit 2 and a message naming the file, the place and what was expected.
expect_fail "no-such.json" "$trivox" info no-such.json
expect_fail "expected" "$trivox" info models
printf '{"trivox": 1, "cells": [' > "$tmp/trunc.json"
expect_fail "trunc.json" "$trivox" info "$tmp/trunc.json"
expect_fail "no such cell; expected one of: block, arch" "$trivox" eval models/graded_block.json --cell nope --uvw 0,0,0
expect_fail "expected 0 <= w <= 1" "$trivox" eval models/graded_block.json --cell arch --uvw 0.5,0.5,1.5
expect_fail "expected 3 comma-separated numbers" "$trivox" eval models/graded_block.json --cell arch --uvw 0.5,0.5
expect_fail "not a finite number" "$trivox" eval models/graded_block.json --cell arch --uvw 0.5,nan,0
expect_fail "" "$trivox" info
expect_fail "" "$trivox" frobnicate
echo "cli info/eval: ok"
