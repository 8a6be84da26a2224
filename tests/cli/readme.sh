#!/usr/bin/env bash
# End-to-end: the quick start of README.md, run as printed, so that the front page cannot drift
# from what trivox does. The scene it shows must be models/quickstart.json byte for byte; every
# `$ build/trivox ...` line of the quick start's console blocks runs with the binary under test,
# its output/ paths moved into a temporary folder; each must exit 0, and every line the README shows under it must be a line of what it printed (whitespace runs
# compared as one space; a line with "..." stands for the lines it abbreviates: the text before
# the "..." must begin one of them). Then the figures the README's text relies on are checked
# from the files and the commands' JSON: the model's cells against the scene, the stack's grid
# against the box and the J750's pitches, the printed volume against the solid's, the VDB's
# grids, and the merge of two shards equal byte for byte to the one-piece stack (inspect, run as
# printed, has already found no slice missing or corrupt: it exits 1 otherwise).
set -euo pipefail
source tests/cli/lib.bash "$@"

# 1. The README's quick start, as printed.
"$py" - "$trivox" "$tmp" README.md <<'PY'
import re, shlex, subprocess, sys
trivox, tmp, readme = sys.argv[1], sys.argv[2], open(sys.argv[3]).read()
m = re.search(r"^## Quick start.*?(?=^## )", readme, re.S | re.M)
assert m, "README.md has no '## Quick start' section"
shown = re.findall(r"^```json\n(.*?)^```", m.group(0), re.S | re.M)
assert shown == [open("models/quickstart.json").read()], "the README's JSON is not models/quickstart.json"
blocks = re.findall(r"^```console\n(.*?)^```", m.group(0), re.S | re.M)
assert blocks, "the quick start has no console block"
norm = lambda s: " ".join(s.split())
moved = lambda s: s.replace("output/", tmp + "/")
runs = 0
for block in blocks:
    steps = []  # [command, [expected lines]]
    for line in block.splitlines():
        if line.startswith("$ "):
            steps.append([line[2:], []])
        else:
            assert steps, f"output before any command: {line!r}"
            steps[-1][1].append(line)
    for command, expected in steps:
        argv = shlex.split(command)
        assert argv[0] == "build/trivox", f"not a trivox command: {command}"
        argv = [trivox] + [moved(a) for a in argv[1:]]
        r = subprocess.run(argv, capture_output=True, text=True)
        assert r.returncode == 0, f"{command}: exit {r.returncode}\n{r.stderr}"
        got = [norm(l) for l in r.stdout.splitlines()]
        for want in expected:
            want = norm(moved(want))
            if want in ("", "..."):
                continue
            if "..." in want:
                head = want.split("...")[0].strip()
                ok = any(g.startswith(head) for g in got)
            else:
                ok = want in got
            assert ok, f"{command}: the README shows {want!r}; trivox printed:\n" + r.stdout
        runs += 1
assert runs >= 9, f"only {runs} commands in the quick start"
print(f"readme: {runs} quick-start commands ran as printed")
PY

# 2. The figures behind them. The scene: a 30 x 16 x 3 plate less a hole of radius 2.5 through
# it, a 4 x 12 wall from z = 1 to 10 (7 mm of it above the plate), a fillet of distance 2 along
# each of the wall's 12 mm sides (each section between nothing and the 2 x 2 right triangle); so
# the box is 30 x 16 x 10 mm, and at J750 pitches (25.4/600, 25.4/300 mm, 27 um layers) the grid
# has ceil(extent / pitch) voxels along each axis.
"$trivox" inspect "$tmp/quickstart-vdb/quickstart.vdb" --json > "$tmp/vdb.json"
"$trivox" merge "$tmp/quickstart-farm" --json > "$tmp/merge.json"
"$py" - "$tmp" <<'PY'
import json, math, sys
t = sys.argv[1]
model = json.load(open(f"{t}/quickstart.json"))
cells = {c["name"]: c for c in model["cells"]}
assert list(cells) == ["plate", "wall", "left.1a", "left.1b", "right.1a", "right.1b"], list(cells)
assert "without" in cells["plate"] and "without" not in cells["wall"], "the plate is the trimmed cell"
man = json.load(open(f"{t}/quickstart/manifest.json"))
pitch = [25.4 / 600, 25.4 / 300, 0.027]
want = [math.ceil(e / p - 1e-9) for e, p in zip([30, 16, 10], pitch)]
assert man["complete"] is True and man["grid"] == want, (man["grid"], want)
assert [l["index"] for l in man["layers"]] == list(range(want[2]))
names = [m["name"] for m in man["materials"]]
per_material = [sum(l["voxels"][i] for l in man["layers"]) for i in range(len(names))]
solid = 30 * 16 * 3 - math.pi * 2.5 ** 2 * 3 + 4 * 12 * 7
fillets = 2 * (2 * 2 / 2) * 12
v = sum(per_material) * pitch[0] * pitch[1] * pitch[2]
assert 0.99 * solid < v < 1.01 * (solid + fillets), (v, solid, fillets)
vdb = json.load(open(f"{t}/vdb.json"))
grids = [g["name"] for g in vdb["grids"]]
assert grids[:3] == ["density", "color", "Cd"] and all(f"material.{n}" in grids for n in names), grids
assert all(abs(x - 0.1) < 1e-9 for g in vdb["grids"] for x in g["voxel_size"]), [g["voxel_size"] for g in vdb["grids"]]
assert 0.99 * solid < vdb["volume_mm3"] < 1.01 * (solid + fillets), vdb["volume_mm3"]
merge = json.load(open(f"{t}/merge.json"))
assert merge["shards"] == 2 and merge["layers"] == want[2], merge
assert merge["material_voxels"] == dict(zip(names, per_material)), (merge["material_voxels"], per_material)
PY

# 3. The shards' merge is the one-piece job, byte for byte.
for f in "$tmp/quickstart"/slice_*.png "$tmp/quickstart/ConfigFile.xml" "$tmp/quickstart/manifest.json"; do
  cmp "$f" "$tmp/quickstart-farm/$(basename "$f")"
done
[ "$(ls "$tmp/quickstart"/slice_*.png | wc -l)" -eq "$(ls "$tmp/quickstart-farm"/slice_*.png | wc -l)" ]
echo "readme: the quick start's model, stack, volume, VDB and merged shards check out"
