#!/usr/bin/env bash
# A real client: Blender imports a trivox VDB headless and renders it (docs/vdb.md, "Units").
# Skipped (exit 77) only when `blender` is not installed (tools/setup.sh installs it).
# Truths:
# - The model is the box [0, 20] x [0, 12] x [0, 8] mm (a trilinear cell), sampled at 0.5 mm
#   from its corner: 40 x 24 x 16 = 15360 voxels, every grid with the same active voxels
#   (counted by OpenVDB's Python module, an independent reader).
# - With --vdb-units m every grid's transform is scale 0.0005 m, index 0 at 0.00025 m, and Blender's
#   bounding box (that of the active voxels' centres, 0.25 mm in from each face) is
#   0.00025 .. 0.01975 x 0.01175 x 0.00775 m: the 20 mm part is 0.02 m, not 20 m. With mm every
#   length is 1000 times larger.
# - The model's property `temperature` (a name Blender renders as temperature) arrives as
#   `property.temperature`; `temperature` itself is absent.
# - Cycles draws the box seen from above as its 20 x 12 mm rectangle: (80 x 48 pixels at 4 pixels
#   per mm) within 10%, in the model's orange.
set -euo pipefail
source "$(dirname "$0")/../cli/lib.bash" "$@"
if ! command -v blender > /dev/null; then echo "blender is not installed: skipped (tools/setup.sh installs it)"; exit 77; fi
script=$(cd "$(dirname "$0")" && pwd)/blender_vdb.py

"$py" - "$tmp/box.json" <<'PY'
import sys, json
pts = []
for z in (0, 8):
    for y in (0, 12):
        for x in (0, 20):
            pts.append([x, y, z, 1.0, 0.5, 0.0, 300 + x])     # orange; temperature 300 + x
m = {"trivox": 1, "units": "mm", "properties": ["r", "g", "b", "temperature"],
     "cells": [{"name": "box", "trivariate": {"orders": [2, 2, 2], "knots": [[0, 0, 1, 1]] * 3, "points": pts}}]}
json.dump(m, open(sys.argv[1], "w"))
PY
"$trivox" slice "$tmp/box.json" -o "$tmp/m" --vdb --vdb-voxel 0.5 --vdb-units m --progress never > /dev/null
"$trivox" slice "$tmp/box.json" -o "$tmp/mm" --vdb --vdb-voxel 0.5 --progress never > /dev/null

# The grids, their types in Blender's terms and their voxel counts, read by OpenVDB's module.
grids=$("$py" - "$tmp/m/box.vdb" "$tmp/mm/box.vdb" <<'PY'
import sys
import pyopenvdb as vdb
for path, unit in zip(sys.argv[1:], ("m", "mm")):
    grids, meta = vdb.readAll(path)
    assert meta["units"] == unit, (path, meta["units"])
    names = {g.name for g in grids}
    assert "temperature" not in names and "property.temperature" in names, names
    for g in grids:
        assert g.activeVoxelCount() == 40 * 24 * 16, (g.name, g.activeVoxelCount())
print(",".join(g.name + ":" + ("VECTOR_FLOAT" if type(g).__name__ == "Vec3SGrid" else "FLOAT") for g in grids))
PY
)

run_blender() {  # LOG ARGS...: Blender's chatter goes to LOG, shown only on failure
  local log=$1; shift
  if ! blender -b --factory-startup --python-exit-code 1 --python "$script" -- "$@" > "$log" 2>&1; then
    echo "blender failed:"; cat "$log"; exit 1
  fi
  grep "^blender_vdb.py:" "$log"
}
run_blender "$tmp/m.log" "$tmp/m/box.vdb" 0.001 0.5 20,12,8 "$grids" "$tmp/box.png"
run_blender "$tmp/mm.log" "$tmp/mm/box.vdb" 1 0.5 20,12,8 "$grids"
