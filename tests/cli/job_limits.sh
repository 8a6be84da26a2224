#!/usr/bin/env bash
# End-to-end: the print job's size and cost bounded before it starts (docs/cli.md, docs/limits.md).
# Truths: --max-voxels and --max-layers refuse before the folder is made, and --force lifts
# neither; --dry-run writes nothing and its counts are the grid's (layers x pixels, a file per
# layer and two more); its memory estimate bounds the peak resident set the job then reaches
# (getrusage), and its slice size is within a factor 2 of the files the job writes; --max-memory
# makes the PNG job run fewer workers (same bytes) or refuses it with the estimate.
set -euo pipefail
source tests/cli/lib.bash "$@"

model=models/graded_block.json      # 40 x 20 x 44 mm

# 1. Output limits, before any folder is made; --force lifts neither.
expect_exit 2 "the job has 8149 layers (44 mm in layers of 0.0054 mm), a file each; expected at most 2000 (limit --max-layers" \
  "$tmp/l1" "$trivox" slice $model -o "$tmp/l1" --dpi 10,10 --layer 0.0054 --max-layers 2000
expect_exit 2 "expected at most 2000 (limit --max-layers" "$tmp/l1" \
  "$trivox" slice $model -o "$tmp/l1" --dpi 10,10 --layer 0.0054 --max-layers 2000 --force
expect_exit 2 "expected at most 1000 voxels (limit --max-voxels" "$tmp/l2" \
  "$trivox" slice $model -o "$tmp/l2" --dpi 100,100 --max-voxels 1e3 --force
# The default: a 150 mm column in layers of a micrometre (150000 files) is refused at once.
cat > "$tmp/column.json" <<'JSON'
{ "trivox": 1, "units": "mm", "cells": [ {"name": "column", "primitive": {"type": "box", "min": [0, 0, 0], "max": [1, 1, 150]}} ] }
JSON
"$trivox" build "$tmp/column.json" -o "$tmp/column_model.json" > /dev/null
expect_exit 2 "the job has 150000 layers (150 mm in layers of 0.001 mm), a file each; expected at most 100000 (limit --max-layers" \
  "$tmp/l3" "$trivox" slice "$tmp/column_model.json" -o "$tmp/l3" --dpi 10,10 --layer 0.001 --force
expect_fail "^trivox: error: --max-layers 0: out of range; expected a whole number of layers, 1 to 1e9" \
  "$trivox" slice $model -o "$tmp/l4" --max-layers 0
expect_fail "^trivox: error: --max-layers: applies to the PNG stack" "$trivox" slice $model -o "$tmp/l4" --vdb --max-layers 10
expect_fail "^trivox: error: --force: with --dry-run" "$trivox" slice $model -o "$tmp/l4" --dry-run --force
expect_fail "^trivox: error: --resume: with --dry-run" "$trivox" slice $model -o "$tmp/l4" --dry-run --resume

# 2. A dry run writes nothing; its counts are the grid's.
grid=(--dpi 600,300 --layer 0.027 --progress never)
"$trivox" slice $model -o "$tmp/dry" "${grid[@]}" --vdb --png --dry-run --json > "$tmp/dry.json"
[ ! -e "$tmp/dry" ] || { echo "--dry-run made the folder"; exit 1; }
"$trivox" slice $model -o "$tmp/dry" "${grid[@]}" --dry-run > "$tmp/dry.txt"
grep -q "^dry run of $model -> $tmp/dry: nothing written" "$tmp/dry.txt"
grep -q "^  memory about .*--max-memory 2 GiB)" "$tmp/dry.txt"
[ ! -e "$tmp/dry" ]

# 3. The job itself, measured: peak resident set within the estimate, slices near it.
"$py" - "$trivox" "$tmp" <<'PY'
import sys, os, json, subprocess, resource
trivox, tmp = sys.argv[1], sys.argv[2]
d = json.load(open(os.path.join(tmp, "dry.json")))
assert d["dry_run"] is True, d
p, v = d["png"], d["vdb"]
nx, ny, nz = p["grid"]
# 40 x 20 x 44 mm at 600 x 300 dpi and 27 um layers: ceil(40 / 25.4 * 600) = 945, ceil(20 / 25.4 * 300) = 237, ceil(44 / 0.027) = 1630
assert (nx, ny, nz) == (945, 237, 1630), p["grid"]
assert p["layers"] == nz and p["files"] == nz + 2 and p["voxels"] == nx * ny * nz, p
assert p["timed_layers"] == 8 and p["estimated_seconds"] > 0 and p["seconds_per_layer"] > 0, p
assert p["estimated_memory_bytes"] > p["memory_held_bytes"] > 0, p
assert v["timed_tasks"] >= 1 and v["estimated_seconds"] > 0 and v["estimated_memory_bytes"] <= d["max_memory_bytes"], v
out = os.path.join(tmp, "run")
r = subprocess.run([trivox, "slice", "models/graded_block.json", "-o", out, "--dpi", "600,300", "--layer", "0.027",
                    "--progress", "never", "--json"], capture_output=True, text=True)
assert r.returncode == 0, r.stderr
peak = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss * 1024
assert peak <= p["estimated_memory_bytes"], (peak, p["estimated_memory_bytes"])
size = sum(os.path.getsize(os.path.join(out, f)) for f in os.listdir(out) if f.startswith("slice_"))
assert p["estimated_output_bytes"] / 2 <= size <= 2 * p["estimated_output_bytes"], (size, p["estimated_output_bytes"])
print(f"dry run: memory {p['estimated_memory_bytes'] / 2**20:.0f} MiB (peak {peak / 2**20:.0f} MiB), "
      f"slices {p['estimated_output_bytes'] / 2**20:.1f} MiB (wrote {size / 2**20:.1f} MiB)")
PY

# 4. --max-memory and the PNG job: layers of 5000 x 2500 pixels (12.5 MB of indices, 50 MB of
#    RGBA each) need more than 64 MiB per worker with 8-layer groups; with --max-memory 256M the
#    job runs ungrouped, and writes the same bytes as without the limit; 64M is refused.
big=(--dpi 3175,3175 --layer 1 --progress never)
"$trivox" slice $model -o "$tmp/m1" "${big[@]}" --dry-run --json --max-memory 256M > "$tmp/m1.json"
"$trivox" slice $model -o "$tmp/m2" "${big[@]}" --dry-run --json > "$tmp/m2.json"
"$py" - "$tmp/m1.json" "$tmp/m2.json" <<'PY'
import sys, json
small, large = (json.load(open(f))["png"] for f in sys.argv[1:])
assert small["estimated_memory_bytes"] <= 256 * 2**20, small
assert large["grouped"] and not small["grouped"], (large, small)
PY
"$trivox" slice $model -o "$tmp/m1" "${big[@]}" --max-memory 256M > /dev/null
"$trivox" slice $model -o "$tmp/m2" "${big[@]}" > /dev/null
for f in "$tmp/m2"/slice_*.png "$tmp/m2/ConfigFile.xml"; do cmp "$f" "$tmp/m1/$(basename "$f")"; done
expect_exit 2 "^trivox: error: --max-memory 64 MiB: the job needs about .* with one worker (.* held already, 5000 x 2500 pixels a layer)" "$tmp/m3" \
  "$trivox" slice $model -o "$tmp/m3" "${big[@]}" --max-memory 64M
