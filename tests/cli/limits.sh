#!/usr/bin/env bash
# End-to-end: input limits (docs/limits.md). Hostile models written by Python: a cell of order
# 20000 (2.4 MB), a 5 MB cell name, a model with a wrong count of control points, a file above
# a lowered size limit, a never-ending device, a G+Smo patch of degree 40, a scene holding an
# order-40 trivariate. Each command that reads them exits 2 with the file, the place and the
# limit, under a 2 GB address-space limit (the order-20000 cell took 1.6 GB in `info` and `eval`
# before the limits); `--limit` and TRIVOX_LIMITS raise them.
set -euo pipefail
source tests/cli/lib.bash "$@"

"$py" - "$tmp" <<'PY'
import json, sys
tmp = sys.argv[1]
def cell(p, name="c"):
    """Order p along u (p control points, x = u evenly spaced), order 2 along v and w."""
    ku = [0.0] * p + [1.0] * p
    pts = [[u / (p - 1), v, w] for w in range(2) for v in range(2) for u in range(p)]
    return {"name": name, "trivariate": {"orders": [p, 2, 2], "knots": [ku, [0, 0, 1, 1], [0, 0, 1, 1]],
                                         "points": pts, "weights": None}}
def model(cells):
    return {"trivox": 1, "units": "mm", "properties": [], "cells": cells}
json.dump(model([cell(20000)]), open(f"{tmp}/o20000.json", "w"))
json.dump(model([cell(40)]), open(f"{tmp}/o40.json", "w"))
json.dump(model([cell(2, "n" * (5 << 20))]), open(f"{tmp}/name.json", "w"))
json.dump(model([cell(2, "n" * 300)]), open(f"{tmp}/name300.json", "w"))
m = model([cell(3, "a"), cell(5, "b")])
del m["cells"][1]["trivariate"]["points"][0]
json.dump(m, open(f"{tmp}/count.json", "w"))
s = {"trivox": 1, "units": "mm", "properties": [], "cells": [cell(40)], "operations": []}
json.dump(s, open(f"{tmp}/scene.json", "w"))
knots = " ".join(["0"] * 41 + ["1"] * 41)
coefs = " ".join(["0"] * (41 * 4 * 3))
open(f"{tmp}/deg40.xml", "w").write(
    '<xml><Geometry type="TensorBSpline3"><Basis type="TensorBSplineBasis3">'
    f'<Basis type="BSplineBasis" index="0"><KnotVector degree="40">{knots}</KnotVector></Basis>'
    '<Basis type="BSplineBasis" index="1"><KnotVector degree="1">0 0 1 1</KnotVector></Basis>'
    '<Basis type="BSplineBasis" index="2"><KnotVector degree="1">0 0 1 1</KnotVector></Basis></Basis>'
    f'<coefs geoDim="3">{coefs}</coefs></Geometry></xml>')
PY

order_msg="o20000.json: /cells/0/trivariate/orders/0: 20000; expected an order of at most 32 (limit max_order; raise it with --limit max_order=N)"
(
  ulimit -v 2000000
  expect_fail "$order_msg" "$trivox" info "$tmp/o20000.json"
  expect_fail "$order_msg" "$trivox" validate "$tmp/o20000.json"
  expect_fail "$order_msg" "$trivox" eval "$tmp/o20000.json" --cell c --uvw 0.5,0.5,0.5
  expect_fail "$order_msg" "$trivox" locate "$tmp/o20000.json" --xyz 0.5,0.5,0.5
  expect_exit 2 "$order_msg" "$tmp/job" "$trivox" slice "$tmp/o20000.json" -o "$tmp/job" --vdb --vdb-voxel 0.1
  expect_fail "name.json: /cells/0/name: a name of 5242880 bytes; expected at most 256 bytes (limit max_name_bytes" \
    "$trivox" info "$tmp/name.json"
)

# Raised: the order-40 cell's volume is exactly 1 (x = u, y = v, z = w).
expect_fail "o40.json: /cells/0/trivariate/orders/0: 40; expected an order of at most 32" "$trivox" info "$tmp/o40.json"
"$trivox" info --json --limit max_order=40 "$tmp/o40.json" > "$tmp/o40.out"
"$py" -c 'import json,sys; j=json.load(open(sys.argv[1])); assert abs(j["volume"] - 1) < 1e-12, j["volume"]' "$tmp/o40.out"
"$trivox" --limit max_order=40 eval "$tmp/o40.json" --cell c --uvw 0.25,0.5,0.5 --json > "$tmp/e40.out"
"$py" -c 'import json,sys; j=json.load(open(sys.argv[1])); assert max(abs(a-b) for a,b in zip(j["point"],[0.25,0.5,0.5])) < 1e-12, j' "$tmp/e40.out"
TRIVOX_LIMITS=max_order=40,max_cells=10 "$trivox" info "$tmp/o40.json" > /dev/null
# --limit overrides the environment.
TRIVOX_LIMITS=max_order=40 expect_fail "40; expected an order of at most 39" "$trivox" info "$tmp/o40.json" --limit max_order=39
expect_fail "name300.json: /cells/0/name: a name of 300 bytes" "$trivox" info "$tmp/name300.json"
"$trivox" info --limit max_name_bytes=300 "$tmp/name300.json" > /dev/null

# A wrong count, refused with the reader's message; a file above the size limit, before reading.
expect_fail "count.json: /cells/1/trivariate/points: 19 control points; expected 20 (5 x 2 x 2, from the knot vectors and orders)" \
  "$trivox" info "$tmp/count.json"
size=$(stat -c %s "$tmp/o40.json")
expect_fail "o40.json: file size: $size bytes; expected at most $((size - 1)) bytes (limit max_file_bytes; raise it with --limit max_file_bytes=N)" \
  "$trivox" info --limit max_order=40 --limit max_file_bytes=$((size - 1)) "$tmp/o40.json"
"$trivox" info --limit max_order=40 --limit max_file_bytes=$size "$tmp/o40.json" > /dev/null
# A device that never ends is read up to the limit, not forever.
expect_fail "/dev/zero: file size: more than 1000000 bytes" timeout 20 "$trivox" info --limit max_file_bytes=1e6 /dev/zero

# G+Smo and scenes.
expect_fail 'deg40.xml: Geometry\[0\] / Basis type="TensorBSplineBasis3" / Basis index="0" / KnotVector (line 1): degree="40"; expected a degree of at most 31 (an order of at most 32) (limit max_order' \
  "$trivox" info "$tmp/deg40.xml"
"$trivox" info --limit max_order=41 "$tmp/deg40.xml" > /dev/null
expect_fail "scene.json: /cells/0/trivariate/orders/0: 40; expected an order of at most 32" \
  "$trivox" build "$tmp/scene.json" -o "$tmp/built.json"

# Malformed limits.
expect_fail "--limit max_order=0: \"0\" is not a whole number from 1 to 1e18" "$trivox" info "$tmp/o40.json" --limit max_order=0
expect_fail "--limit order=3: unknown limit \"order\"; expected one of max_file_bytes, max_order" "$trivox" info "$tmp/o40.json" --limit order=3
TRIVOX_LIMITS=max_order expect_fail "TRIVOX_LIMITS max_order: no '='" "$trivox" info "$tmp/o40.json"
echo "limits: ok"
