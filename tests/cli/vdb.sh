#!/usr/bin/env bash
# End-to-end: `trivox slice --vdb` writes an OpenVDB file that independent readers (OpenVDB's
# Python module, vdb_print) agree with; `trivox inspect FILE.vdb` and `trivox render` read it.
# Truths:
# - Fichera corner ([-1,1]^3 minus the octant x < 0, y < 0, z > 0 in models/gismo/fichera.xml,
#   volume 7) at voxel 0.25 from the box
#   corner (-1,-1,-1): faces on voxel boundaries, centres off them: the active voxels are the 448
#   whose centres lie in the solid, 448 x 0.25^3 = 7 mm^3.
# - At voxel 0.3 with --supersample 2 the density of a voxel is the share of its 8 sub-cube
#   centres (-1 + 0.3 i + 0.15 (s + 1/2)) in the solid: counted here exactly.
# - Colours equal `trivox locate` at voxel centres within the sampler's 1/512; fractions follow
#   the subtractive conversion of materials.md (C = m - r, ..., K = 1 - m, W = r + g + b - 2m).
#   `color` holds them decoded to linear by IEC 61966-2-1 (c <= 0.04045: c / 12.92, else
#   ((c + 0.055) / 1.055)^2.4, computed here), or as they are with --vdb-color-space srgb.
# - --vdb-units m divides every length by 1000 and changes no value; shards merge to the same bytes.
# - A box with linear properties: property grids equal the linear function at voxel centres.
set -euo pipefail
source "$(dirname "$0")/lib.bash" "$@"
q="--progress never"

# --- Fichera corner: exact occupancy, metadata, determinism across thread counts -------------
"$trivox" slice models/gismo/fichera.xml -o "$tmp/f1" --vdb --vdb-voxel 0.25 --threads 1 $q --json > "$tmp/f1.json"
"$trivox" slice models/gismo/fichera.xml -o "$tmp/f2" --vdb --vdb-voxel 0.25 --threads 2 $q > "$tmp/f2.txt"
cmp "$tmp/f1/fichera.vdb" "$tmp/f2/fichera.vdb"       # byte-identical for 1 and 2 threads
# --vdb alone: no PNG stack, no ConfigFile.xml; the manifest lists the VDB with its digest.
[ "$(ls -A "$tmp/f1" | tr '\n' ' ')" = "fichera.vdb manifest.json " ]
cmp "$tmp/f1/manifest.json" "$tmp/f2/manifest.json"
"$py" -c "
import json, hashlib, sys
m = json.load(open('$tmp/f1/manifest.json'))
f = {x['role']: x for x in m['files']}
assert m['complete'] and m['options']['png'] == 'no' and m['layers'] == [], m
assert f['vdb']['sha256'] == hashlib.sha256(open('$tmp/f1/fichera.vdb', 'rb').read()).hexdigest()
"
grep -q "448 (0 fractional)" "$tmp/f2.txt"
"$trivox" --version > "$tmp/version"

"$py" - "$tmp/f1/fichera.vdb" "$tmp/f1.json" models/gismo/fichera.xml "$tmp/version" <<'PY'
import sys, json, hashlib, struct
import pyopenvdb as vdb
path, summary, model, version = sys.argv[1], json.load(open(sys.argv[2])), sys.argv[3], open(sys.argv[4]).read().strip()
# The grids in file order, from the file layout itself (OpenVDB's File API lists them by name):
# header (magic, format, library version, offsets flag, 36-character UUID), file metadata,
# grid count, then per grid a descriptor (name, type, instance parent, 3 offsets) and its data.
b = open(path, "rb").read()
i32 = lambda p: struct.unpack_from("<i", b, p)[0]
def text(p):
    n = i32(p)
    return b[p + 4:p + 4 + n].decode(), p + 4 + n
assert struct.unpack_from("<q", b, 0)[0] == 0x56444220
uuid = b[21:57].decode()
assert uuid[14] == "8" and uuid[19] in "89ab", uuid           # version 8 (derived), RFC variant
zeroed = b[:21] + b"00000000-0000-0000-0000-000000000000" + b[57:]
h = hashlib.sha256(zeroed).hexdigest()
assert uuid.replace("-", "")[:12] == h[:12], (uuid, h)          # from the file's own digest
pos = 57
n_meta, pos = i32(pos), pos + 4
for _ in range(n_meta):
    _, pos = text(pos)
    _, pos = text(pos)
    pos += 4 + i32(pos)
n_grids, pos = i32(pos), pos + 4
order = []
for _ in range(n_grids):
    name, pos = text(pos)
    gtype, pos = text(pos)
    parent, pos = text(pos)
    grid_pos, block_pos, end_pos = struct.unpack_from("<qqq", b, pos)
    order.append((name, gtype))
    pos = end_pos
palette = ["VeroCyan-V", "VeroMagenta-V", "VeroYellow-V", "VeroBlack", "VeroUltraWhite", "UltraClear"]
names = ["density", "color", "Cd"] + ["material." + m for m in palette]
assert [n for n, _ in order] == names, order
assert [t for _, t in order] == ["Tree_float_5_4_3"] + ["Tree_vec3s_5_4_3"] * 2 + ["Tree_float_5_4_3"] * 6, order

grids, meta = vdb.readAll(path)
grids = sorted(grids, key=lambda g: names.index(g.name))         # back into file order
assert type(grids[0]).__name__ == "FloatGrid" and grids[0].gridClass == "fog volume", (type(grids[0]), grids[0].gridClass)
assert all(type(g).__name__ == "Vec3SGrid" for g in grids[1:3])
assert all(type(g).__name__ == "FloatGrid" for g in grids[3:])
sha = hashlib.sha256(open(model, "rb").read()).hexdigest()
expect = {"units": "mm", "generator": version, "source": "fichera.xml", "source_sha256": sha,
          "voxel_size": 0.25, "supersample": 1, "palette": "vero"}
for m in (meta, grids[0].metadata, grids[4].metadata):
    for k, v in expect.items():
        assert m.get(k) == v, (k, m.get(k), v)
# World placement: index (0,0,0) is the centre of the voxel at the box corner (-1,-1,-1).
t = grids[0].transform
assert all(abs(a - b) < 1e-12 for a, b in zip(t.indexToWorld((0, 0, 0)), (-0.875,) * 3)), t.indexToWorld((0, 0, 0))
assert all(abs(a - 0.25) < 1e-15 for a in t.voxelSize())

def active(g):
    out = {}
    for it in g.citerOnValues():
        assert it["count"] == 1, "unexpected tile"
        out[tuple(it["min"])] = it["value"]
    return out
dens = active(grids[0])
inside = set()
for i in range(8):
    for j in range(8):
        for k in range(8):
            c = [-1 + (n + 0.5) * 0.25 for n in (i, j, k)]
            if not (c[0] < 0 and c[1] < 0 and c[2] > 0):
                inside.add((i, j, k))
assert set(dens) == inside and len(inside) == 448, (len(dens), len(inside))
assert all(v == 1.0 for v in dens.values())
assert abs(len(dens) * 0.25 ** 3 - 7.0) < 1e-12
for g in grids[1:]:
    vals = active(g)
    assert set(vals) == inside, g.name                   # topology of every grid = density's
    if g.name in ("color", "Cd"):
        assert all(v == (1.0, 1.0, 1.0) for v in vals.values()), g.name   # default material: white
    else:
        want = 1.0 if g.name == "material.VeroUltraWhite" else 0.0
        assert all(v == want for v in vals.values()), g.name
v = summary["vdb"]
assert v["active_voxels"] == 448 and abs(v["volume_mm3"] - 7) < 1e-9 and v["inversion_failures"] == 0, v
assert v["sha256"] == hashlib.sha256(open(path, "rb").read()).hexdigest()
PY

# Independent tools: vdb_print lists the grids.
vdb_print -l "$tmp/f1/fichera.vdb" > "$tmp/print.txt"
for g in density color Cd material.VeroCyan-V material.VeroUltraWhite material.UltraClear; do
  grep -q "^Name: $g\$" "$tmp/print.txt" || { echo "vdb_print lacks $g"; cat "$tmp/print.txt"; exit 1; }
done
[ "$(grep -c "^Name: " "$tmp/print.txt")" -eq 9 ]
grep -q "^  class: fog volume\$" "$tmp/print.txt"
grep -q "^  units: mm\$" "$tmp/print.txt"

# inspect: grids, volume per material.
"$trivox" inspect "$tmp/f1/fichera.vdb" > "$tmp/inspect.txt"
grep -q "^density  *float  *fog volume  *0.25  *448" "$tmp/inspect.txt" || { cat "$tmp/inspect.txt"; exit 1; }
grep -q "^volume: 7 mm^3" "$tmp/inspect.txt"
"$trivox" inspect "$tmp/f1/fichera.vdb" --json > "$tmp/inspect.json"
"$py" - "$tmp/inspect.json" <<'PY'
import sys, json
r = json.load(open(sys.argv[1]))
assert r["kind"] == "vdb" and len(r["grids"]) == 9 and r["units"] == "mm", r
d = r["grids"][0]
assert d["name"] == "density" and d["class"] == "fog volume" and d["type"] == "float" and d["active_voxels"] == 448, d
assert d["index_bounds"] == [[0, 0, 0], [7, 7, 7]], d["index_bounds"]
assert all(abs(a - b) < 1e-12 for a, b in zip(sum(d["world_bounds"], []), [-1, -1, -1, 1, 1, 1])), d["world_bounds"]
assert d["min"] == 1 and d["max"] == 1 and d["mean"] == 1 and d["voxel_size"] == [0.25] * 3
c = r["grids"][1]
assert c["type"] == "vec3s" and c["min"] == [1, 1, 1] and c["active_voxels"] == 448, c
assert abs(r["volume_mm3"] - 7) < 1e-12
mats = {m["name"]: m["volume_mm3"] for m in r["materials"]}
assert abs(mats["VeroUltraWhite"] - 7) < 1e-12 and mats["VeroCyan-V"] == 0 and len(mats) == 6, mats
assert r["metadata"]["voxel_size"] == 0.25 and r["metadata"]["supersample"] == 1
PY

# --- Supersampling: fractional density exactly where the boundary cuts a voxel ----------------
"$trivox" slice models/gismo/fichera.xml -o "$tmp/s2" --vdb --vdb-voxel 0.3 --supersample 2 $q --json > "$tmp/s2.json"
"$py" - "$tmp/s2/fichera.vdb" "$tmp/s2.json" <<'PY'
import sys, json
import pyopenvdb as vdb
grids, meta = vdb.readAll(sys.argv[1])
v = json.load(open(sys.argv[2]))["vdb"]
assert meta["supersample"] == 2 and v["grid"]["count"] == [7, 7, 7], (meta, v["grid"])
grids = {g.name: g for g in grids}
dens = {tuple(it["min"]): it["value"] for it in grids["density"].citerOnValues()}
inside = lambda p: all(-1 < x < 1 for x in p) and not (p[0] < 0 and p[1] < 0 and p[2] > 0)
want, fractional = {}, 0
for i in range(7):
    for j in range(7):
        for k in range(7):
            n = sum(inside([-1 + 0.3 * a + 0.15 * (s + 0.5) for a, s in zip((i, j, k), (si, sj, sk))])
                    for si in (0, 1) for sj in (0, 1) for sk in (0, 1))
            if n:
                want[(i, j, k)] = n / 8
                fractional += n < 8
assert dens == want, [(c, dens.get(c), want.get(c)) for c in set(dens) | set(want) if dens.get(c) != want.get(c)][:5]
assert v["fractional_voxels"] == fractional > 0
volume = sum(want.values()) * 0.3 ** 3
# 1.95^3 - 1.05 x 1.05 x 0.9: 13 of the 14 sub-sample planes per axis lie in [-1, 1], 7 below 0, 6 above.
assert abs(v["volume_mm3"] - volume) < 1e-9 and abs(volume - (1.95 ** 3 - 1.05 * 1.05 * 0.9)) < 1e-9, (v["volume_mm3"], volume)
for g in grids.values():
    assert {tuple(it["min"]) for it in g.citerOnValues()} == set(want), g.name
PY

# A curved model: the supersampled volume is within a few percent of the quadrature volume.
"$trivox" info models/twisted_column.json --json > "$tmp/col-info.json"
"$trivox" slice models/twisted_column.json -o "$tmp/col" --vdb --vdb-voxel 0.8 --supersample 2 $q --json > "$tmp/col.json"
"$py" - "$tmp/col/twisted_column.vdb" "$tmp/col.json" "$tmp/col-info.json" <<'PY'
import sys, json
import pyopenvdb as vdb
grids, meta = vdb.readAll(sys.argv[1])
v, exact = json.load(open(sys.argv[2]))["vdb"], json.load(open(sys.argv[3]))["volume"]
d = [g for g in grids if g.name == "density"][0]
total = sum(it["value"] for it in d.citerOnValues()) * 0.8 ** 3
assert abs(total - v["volume_mm3"]) < 1e-6 * exact and abs(total - exact) / exact < 0.02, (total, exact)
# Fractional voxels only near the boundary: a voxel with a sub-sample outside lies within half a
# voxel diagonal of the surface, so (the surface being nearly flat at this scale) some voxel
# within 2 steps has all its sub-samples outside, i.e. is not active; voxels with no such
# neighbour are full.
values = {tuple(it["min"]): it["value"] for it in d.citerOnValues()}
offsets = [(a, b, e) for a in range(-2, 3) for b in range(-2, 3) for e in range(-2, 3)]
near = lambda c: any((c[0] + a, c[1] + b, c[2] + e) not in values for a, b, e in offsets)
frac = [c for c, x in values.items() if x < 1]
assert frac and all(near(c) for c in frac), "fractional voxel away from the boundary"
interior = [c for c in values if not near(c)]
assert interior and all(values[c] == 1 for c in interior)
PY

# --- Colours and fractions against trivox locate; both outputs at once -----------------------
# 25 dpi is 1.016 mm: the PNG stack's voxels are cubes of the VDB's voxel size.
"$trivox" slice models/graded_block.json -o "$tmp/g1" --png --vdb --dpi 25,25 --layer 1.016 --vdb-voxel 1.016 --threads 1 $q --json > "$tmp/g1.json"
"$trivox" slice models/graded_block.json -o "$tmp/g2" --vdb --vdb-voxel 1.016 --threads 2 $q > /dev/null
cmp "$tmp/g1/graded_block.vdb" "$tmp/g2/graded_block.vdb"
# The PNG stack written with the VDB (the model's box measured once for both jobs) is the stack
# written alone.
"$trivox" slice models/graded_block.json -o "$tmp/g3" --dpi 25,25 --layer 1.016 --threads 2 $q > /dev/null
for f in "$tmp"/g3/slice_*.png "$tmp/g3/ConfigFile.xml"; do cmp "$f" "$tmp/g1/$(basename "$f")"; done
[ -f "$tmp/g1/ConfigFile.xml" ]
[ -f "$tmp/g1/slice_0.png" ]
"$py" - "$tmp/g1" <<'PY'
import sys, json, hashlib, os
d = sys.argv[1]
m = json.load(open(os.path.join(d, "manifest.json")))      # the job's manifest lists the VDB
vdb = [f for f in m["files"] if f["role"] == "vdb"]
assert m["complete"] and len(vdb) == 1 and vdb[0]["file"] == "graded_block.vdb", m["files"]
assert vdb[0]["sha256"] == hashlib.sha256(open(os.path.join(d, "graded_block.vdb"), "rb").read()).hexdigest()
assert m["options"]["vdb"] == "yes" and m["options"]["vdb.voxel_mm"] == "1.016" and m["options"]["vdb.supersample"] == "1", m["options"]
assert "vdb.units" not in m["options"] and "vdb.color_space" not in m["options"], m["options"]   # defaults
PY
"$trivox" slice models/graded_block.json -o "$tmp/g4" --vdb --vdb-voxel 1.016 --vdb-color-space srgb $q > /dev/null
"$py" - "$tmp/g4/graded_block.vdb" "$tmp/g1.json" "$trivox" models/graded_block.json "$tmp/g1/graded_block.vdb" <<'PY'
import sys, json, subprocess
import pyopenvdb as vdb
path, summary, trivox, model, linear_path = sys.argv[1], json.load(open(sys.argv[2])), sys.argv[3], sys.argv[4], sys.argv[5]
grids, meta = vdb.readAll(path)
g = {x.name: x for x in grids}
lgrids, lmeta = vdb.readAll(linear_path)
lg = {x.name: x for x in lgrids}
decode = lambda c: c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4
assert meta["color_space"] == "srgb" and lmeta["color_space"] == "linear" and g["Cd"].metadata["color_space"] == "srgb"
assert {k: v for k, v in meta.items() if k != "color_space"} == {k: v for k, v in lmeta.items() if k != "color_space"}
# The two files differ in color and Cd only, by the decode.
values = lambda grid: {tuple(it["min"]): it["value"] for it in grid.citerOnValues()}
for name in g:
    a, b = values(g[name]), values(lg[name])
    assert set(a) == set(b), name
    if name in ("color", "Cd"):
        assert all(abs(decode(x) - y) < 1e-6 for c in a for x, y in zip(a[c], b[c])), name
    else:
        assert a == b, name
lcolor = values(lg["color"])
dens = {tuple(it["min"]): it["value"] for it in g["density"].citerOnValues()}
# Same grid as the 1.016 mm PNG stack (origin and pitch): the same voxels are filled.
assert len(dens) == summary["filled"] == summary["vdb"]["active_voxels"], (len(dens), summary["filled"])
assert abs(len(dens) - 9600 / 1.016**3) / 9600 < 0.03
color = {tuple(it["min"]): it["value"] for it in g["color"].citerOnValues()}
assert set(color) == set(dens)
palette = ["VeroCyan-V", "VeroMagenta-V", "VeroYellow-V", "VeroBlack", "VeroUltraWhite", "UltraClear"]
fr = {m: {tuple(it["min"]): it["value"] for it in g["material." + m].citerOnValues()} for m in palette}
for m in palette:
    assert set(fr[m]) == set(dens), m
for c in dens:
    s = sum(fr[m][c] for m in palette)
    assert abs(s - 1) < 1e-5, (c, s)
# A few voxels, spread over both cells: colour = the located properties at the centre.
keys = sorted(dens)
t = g["color"].transform
for c in keys[:: len(keys) // 7]:
    x, y, z = t.indexToWorld(c)
    out = json.loads(subprocess.run([trivox, "locate", model, "--xyz", f"{x!r},{y!r},{z!r}", "--json"],
                                    check=True, capture_output=True, text=True).stdout)
    assert out["inside"], (c, out)
    rgb = [out["properties"][k] for k in "rgb"]
    assert all(abs(a - min(max(b, 0), 1)) < 1 / 512 + 1e-6 for a, b in zip(color[c], rgb)), (c, color[c], rgb)
    # Linear: the decode's slope is at most 2.3, so the sampler's 1/512 grows to 2.3 / 512.
    assert all(abs(a - decode(min(max(b, 0), 1))) < 2.3 / 512 + 1e-6 for a, b in zip(lcolor[c], rgb)), (c, lcolor[c], rgb)
    # Subtractive conversion (materials.md) of the voxel's colour.
    r, gg, b = color[c]
    mx = max(r, gg, b)
    cmykw = [mx - r, mx - gg, mx - b, 1 - mx, r + gg + b - 2 * mx]
    if cmykw[4] < 0:
        cmykw[4] = 0
        s4 = sum(cmykw[:4])
        cmykw = [x / s4 for x in cmykw[:4]] + [0]
    got = [fr[m][c] for m in palette[:5]]
    assert all(abs(a - b) < 1e-4 for a, b in zip(got, cmykw)), (c, got, cmykw)
PY

# --- Extra properties: their own grids, exact for a linear box --------------------------------
"$py" - "$tmp/props.json" <<'PY'
import sys, json
pts = []
for z in (0, 4):
    for y in (0, 4):
        for x in (0, 4):
            # r g b (grey 0.5), stiffness 100 + 10 x, UltraClear z / 16 (a palette material), density 7,
            # temperature 300 + y (density and temperature: names Blender and Houdini give a meaning)
            pts.append([x, y, z, 0.5, 0.5, 0.5, 100 + 10 * x, z / 16, 7, 300 + y])
m = {"trivox": 1, "units": "mm", "properties": ["r", "g", "b", "stiffness", "UltraClear", "density", "temperature"],
     "cells": [{"name": "box", "trivariate": {"orders": [2, 2, 2], "knots": [[0, 0, 1, 1]] * 3, "points": pts}}]}
json.dump(m, open(sys.argv[1], "w"))
PY
"$trivox" slice "$tmp/props.json" -o "$tmp/p" --vdb --vdb-voxel 0.5 $q > /dev/null
"$py" - "$tmp/p/props.vdb" <<'PY'
import sys
import pyopenvdb as vdb
grids, meta = vdb.readAll(sys.argv[1])
g = {x.name: x for x in grids}
assert len(grids) == 12 and {"stiffness", "property.density", "property.temperature"} <= set(g), sorted(g)
assert "temperature" not in g, sorted(g)
assert g["property.density"].metadata["property"] == "density"
assert g["property.temperature"].metadata["property"] == "temperature"
grey = ((0.5 + 0.055) / 1.055) ** 2.4            # 0.5 decoded (IEC 61966-2-1): 0.2140...
t = g["density"].transform
def vals(name):
    return {tuple(it["min"]): it["value"] for it in g[name].citerOnValues()}
dens = vals("density")
assert len(dens) == 512
for name in ("stiffness", "property.density", "property.temperature", "material.UltraClear", "material.VeroBlack",
             "material.VeroUltraWhite"):
    assert set(vals(name)) == set(dens), name
for c, s in vals("stiffness").items():
    x, y, z = t.indexToWorld(c)
    assert abs(s - (100 + 10 * x)) < 1e-4, (c, s)
    assert abs(g["property.density"].getConstAccessor().getValue(c) - 7) < 1e-5
    assert abs(g["property.temperature"].getConstAccessor().getValue(c) - (300 + y)) < 1e-4
    clear = z / 16
    assert abs(g["material.UltraClear"].getConstAccessor().getValue(c) - clear) < 1e-5
    assert abs(g["material.VeroBlack"].getConstAccessor().getValue(c) - (1 - clear) / 2) < 1e-5
    assert all(abs(a - grey) < 1e-6 for a in g["color"].getConstAccessor().getValue(c))
PY

# --- Units: metres (Blender, Houdini) -----------------------------------------------------------
"$trivox" slice models/gismo/fichera.xml -o "$tmp/fm" --vdb --vdb-voxel 0.25 --vdb-units m $q --json > "$tmp/fm.json"
"$py" - "$tmp/fm/fichera.vdb" "$tmp/f1/fichera.vdb" "$tmp/fm/manifest.json" <<'PY'
import sys, json
import pyopenvdb as vdb
m_grids, m_meta = vdb.readAll(sys.argv[1])
mm_grids, mm_meta = vdb.readAll(sys.argv[2])
assert m_meta["units"] == "m" and m_meta["voxel_size"] == 0.25 / 1000, m_meta
assert {k: v for k, v in m_meta.items() if k not in ("units", "voxel_size")} == \
       {k: v for k, v in mm_meta.items() if k not in ("units", "voxel_size")}
mm = {g.name: g for g in mm_grids}
for g in m_grids:
    assert g.metadata["units"] == "m", g.name
    t = g.transform
    assert all(abs(a - 0.25e-3) < 1e-18 for a in t.voxelSize()), t.voxelSize()
    assert all(abs(a + 0.875e-3) < 1e-15 for a in t.indexToWorld((0, 0, 0))), t.indexToWorld((0, 0, 0))
    assert all(abs(a - 0.875e-3) < 1e-15 for a in t.indexToWorld((7, 7, 7))), t.indexToWorld((7, 7, 7))
    values = lambda grid: {tuple(it["min"]): it["value"] for it in grid.citerOnValues()}
    assert values(g) == values(mm[g.name]), g.name           # the same voxels and values
assert json.load(open(sys.argv[3]))["options"]["vdb.units"] == "m"
PY
# inspect reports the world in the file's unit: the Fichera corner [-1, 1]^3 mm is [-0.001, 0.001]^3 m.
"$trivox" inspect "$tmp/fm/fichera.vdb" > "$tmp/fm-inspect.txt"
grep -q "^volume: 7e-09 m^3" "$tmp/fm-inspect.txt" || { cat "$tmp/fm-inspect.txt"; exit 1; }
"$trivox" inspect "$tmp/fm/fichera.vdb" --json > "$tmp/fm-inspect.json"
"$py" - "$tmp/fm-inspect.json" <<'PY'
import sys, json
r = json.load(open(sys.argv[1]))
assert r["units"] == "m" and r["metadata"]["units"] == "m", r["units"]
d = r["grids"][0]
assert all(abs(a - b) < 1e-15 for a, b in zip(sum(d["world_bounds"], []), [-1e-3] * 3 + [1e-3] * 3)), d["world_bounds"]
assert all(abs(a - 0.25e-3) < 1e-18 for a in d["voxel_size"]) and d["active_voxels"] == 448
# The JSON's volumes are in mm^3 whatever the file's unit: 448 voxels of 0.25 mm = 7 mm^3.
assert abs(r["volume_mm3"] - 7) < 1e-9, r["volume_mm3"]
assert abs(sum(m["volume_mm3"] for m in r["materials"]) - 7) < 1e-6, r["materials"]
PY
# render draws the same picture whatever the unit (the view is fitted to the volume).
"$trivox" render "$tmp/fm/fichera.vdb" -o "$tmp/fm.png" --size 64,64 --json > "$tmp/fm-render.json"
"$trivox" render "$tmp/f1/fichera.vdb" -o "$tmp/f1.png" --size 64,64 --json > "$tmp/f1-render.json"
"$py" -c "
import json, sys
a, b = (json.load(open(p)) for p in sys.argv[1:])
assert a['covered_pixels'] == b['covered_pixels'] > 1000, (a, b)
" "$tmp/fm-render.json" "$tmp/f1-render.json"
# Shards in metres merge to the file of the whole job.
"$trivox" slice models/gismo/fichera.xml -o "$tmp/fs" --vdb --vdb-voxel 0.125 --vdb-units m --shard 0/2 $q > /dev/null
"$trivox" slice models/gismo/fichera.xml -o "$tmp/fs" --vdb --vdb-voxel 0.125 --vdb-units m --shard 1/2 $q > /dev/null
# The merge reads the parts whole: it needs no temporary folder (OpenVDB's delayed loading
# would copy each part into $TMPDIR, and warn when it cannot).
TMPDIR="$tmp/no-such-folder" "$trivox" merge "$tmp/fs" > /dev/null 2> "$tmp/merge.err"
[ ! -s "$tmp/merge.err" ] || { cat "$tmp/merge.err"; exit 1; }
"$trivox" slice models/gismo/fichera.xml -o "$tmp/fw" --vdb --vdb-voxel 0.125 --vdb-units m $q > /dev/null
cmp "$tmp/fs/fichera.vdb" "$tmp/fw/fichera.vdb"

# --- render: a picture of the volume ----------------------------------------------------------
"$trivox" render "$tmp/g1/graded_block.vdb" -o "$tmp/top.png" --view +z --size 80,60 > /dev/null
"$trivox" render "$tmp/g1/graded_block.vdb" -o "$tmp/iso.png" --background transparent --json > "$tmp/iso.json"
"$py" - "$tmp/top.png" "$tmp/iso.png" "$tmp/iso.json" <<'PY'
import sys, json
import OpenImageIO as oiio
def read(p):
    i = oiio.ImageInput.open(p)
    s = i.spec()
    px = i.read_image(format="uint8")
    i.close()
    return s, px
s, px = read(sys.argv[1])
assert (s.width, s.height, s.nchannels) == (80, 60, 4)
assert tuple(px[0][0]) == (255, 255, 255, 255)          # background
c = tuple(int(x) for x in px[30][40])
assert c[3] == 255 and c[:3] != (255, 255, 255), c      # the block, seen from above
s, px = read(sys.argv[2])
r = json.load(open(sys.argv[3]))
assert (s.width, s.height) == (r["width"], r["height"]) and max(r["width"], r["height"]) == 800, r
assert px[0][0][3] == 0 and r["covered_pixels"] > 0.1 * r["width"] * r["height"], r
assert r["density_grid"] == "density" and r["color_grid"] == "color"
PY
# OpenVDB's own renderer draws the fog volume. (Run in the folder: vdb_render takes the extension
# from the first dot in the whole output path, and mktemp's folder name has one.)
(cd "$tmp" && vdb_render f1/fichera.vdb vr.ppm -name density -res 32x32 -translate 0,0,6) > "$tmp/vr.txt" 2>&1 ||
  { echo "vdb_render failed:"; cat "$tmp/vr.txt"; exit 1; }
"$py" - "$tmp/vr.ppm" <<'PY'
import sys
head, size, depth, px = open(sys.argv[1], "rb").read().split(b"\n", 3)
assert (head, size, depth, len(px)) == (b"P6", b"32 32", b"255", 32 * 32 * 3)
assert len({px[i:i + 3] for i in range(0, len(px), 3)}) > 10     # the volume, not a blank frame
PY

# --- Refusals: exit 2, a message naming the option or file, no file left behind ----------------
expect_fail "expected a voxel edge in mm" "$trivox" slice models/gismo/fichera.xml -o "$tmp/x1" --vdb --vdb-voxel 0
expect_fail "expected a voxel edge in mm" "$trivox" slice models/gismo/fichera.xml -o "$tmp/x1" --vdb --vdb-voxel -1
expect_fail "a larger --vdb-voxel, or --force" "$trivox" slice models/gismo/fichera.xml -o "$tmp/x1" --vdb --vdb-voxel 1e-4
# Voxels OpenVDB's transforms refuse (an edge under cbrt(3e-15) = 1.44e-5 in the file's unit),
# refused before a file or manifest is written, even with --force.
expect_fail "expected at least 1.44225e-05 mm, the smallest voxel OpenVDB's transforms take in mm" \
  "$trivox" slice models/gismo/fichera.xml -o "$tmp/x1" --vdb --vdb-voxel 1e-7 --force
expect_fail "a voxel of 1e-05 m; expected at least 0.0144225 mm" \
  "$trivox" slice models/gismo/fichera.xml -o "$tmp/x1" --vdb --vdb-voxel 0.01 --vdb-units m --force
# Memory: a voxel whose grids would not fit in --max-memory is refused before anything is
# written; the automatic voxel fits, and the job's peak (resident set, measured by the kernel)
# stays within it.
expect_fail "an estimated .* of memory; expected at most 256 MiB (raise --max-memory, or a larger --vdb-voxel)" \
  "$trivox" slice models/graded_block.json -o "$tmp/x1" --vdb --vdb-voxel 0.05 --max-memory 256M --force
expect_fail "--max-memory 64K: not a memory size" "$trivox" slice models/graded_block.json -o "$tmp/x1" --vdb --max-memory 64K
"$py" - "$trivox" "$tmp/mem" <<'PY'
import sys, json, resource, subprocess
trivox, out = sys.argv[1:]
limit = 300 * 2**20
r = subprocess.run([trivox, "slice", "models/graded_block.json", "-o", out, "--vdb", "--max-memory", "300M", "--json",
                    "--progress", "never"], capture_output=True, text=True)
assert r.returncode == 0, r.stderr
v = json.loads(r.stdout)["vdb"]
peak = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss * 1024
assert v["voxel_automatic"] and v["estimated_memory_bytes"] <= limit, v
assert peak <= limit, (peak, limit, v["voxel_mm"])
assert abs(v["volume_mm3"] - 9600) < 0.05 * 9600, v["volume_mm3"]     # the graded block's 40 x 20 x 12 mm
PY
expect_fail "expected 1 to 8" "$trivox" slice models/gismo/fichera.xml -o "$tmp/x1" --vdb --supersample 0
expect_fail "expected 1 to 8" "$trivox" slice models/gismo/fichera.xml -o "$tmp/x1" --vdb --supersample 9
expect_fail "expected --vdb with it" "$trivox" slice models/gismo/fichera.xml -o "$tmp/x1" --supersample 2
expect_fail "^trivox: error: --vdb-units: applies to the VDB output; expected --vdb with it" \
  "$trivox" slice models/gismo/fichera.xml -o "$tmp/x1" --vdb-units m
expect_fail "^trivox: error: --vdb-color-space: applies to the VDB output" \
  "$trivox" slice models/gismo/fichera.xml -o "$tmp/x1" --vdb-color-space srgb
expect_fail "^trivox: error: --vdb-units cm: unknown unit; expected mm or m" \
  "$trivox" slice models/gismo/fichera.xml -o "$tmp/x1" --vdb --vdb-units cm
expect_fail "^trivox: error: --vdb-color-space rgb: unknown colour space; expected linear or srgb" \
  "$trivox" slice models/gismo/fichera.xml -o "$tmp/x1" --vdb --vdb-color-space rgb
expect_fail "expected --png with it" "$trivox" slice models/gismo/fichera.xml -o "$tmp/x1" --vdb --zip
expect_fail "expected 1 to 8" "$trivox" slice models/gismo/fichera.xml -o "$tmp/x1" --png --vdb --supersample 9 --dpi 100,100
[ ! -e "$tmp/x1" ]                                        # nothing written, not even the PNG stack
expect_fail "not empty" "$trivox" slice models/gismo/fichera.xml -o "$tmp/f1" --vdb --vdb-voxel 0.25
expect_fail "teapot.xml: no cells; expected" "$trivox" slice models/gismo/teapot.xml -o "$tmp/x2" --vdb
expect_fail "missing.vdb: no such file" "$trivox" inspect "$tmp/missing.vdb"
# A damaged name (a byte that is not UTF-8) still reads, and prints as JSON.
"$py" -c 'import sys; b = open(sys.argv[1], "rb").read(); open(sys.argv[2], "wb").write(b.replace(b"density", b"\xffensity"))' \
  "$tmp/f1/fichera.vdb" "$tmp/badname.vdb"
"$trivox" inspect "$tmp/badname.vdb" --json > "$tmp/badname.json"
"$py" -c 'import json, sys; r = json.load(open(sys.argv[1])); assert any(g["name"] == "\ufffdensity" for g in r["grids"]), r["grids"]' "$tmp/badname.json"
echo "not a volume" > "$tmp/text.vdb"
expect_fail "text.vdb: no OpenVDB magic number" "$trivox" inspect "$tmp/text.vdb"
head -c 600 "$tmp/f1/fichera.vdb" > "$tmp/cut.vdb"
expect_fail "cut.vdb: truncated or corrupt" "$trivox" inspect "$tmp/cut.vdb"
size=$(stat -c %s "$tmp/f1/fichera.vdb")
head -c $((size - 100)) "$tmp/f1/fichera.vdb" > "$tmp/cut2.vdb"
expect_fail "cut2.vdb: " "$trivox" inspect "$tmp/cut2.vdb"
expect_fail "expected an OpenVDB file" "$trivox" render "$tmp/cut.vdb" -o "$tmp/x.png"
expect_fail "unknown view; expected +z" "$trivox" render "$tmp/f1/fichera.vdb" -o "$tmp/x.png" --view diagonal
expect_fail "expected two whole numbers" "$trivox" render "$tmp/f1/fichera.vdb" -o "$tmp/x.png" --size 0,10
expect_fail "--size 10: 1 numbers" "$trivox" render "$tmp/f1/fichera.vdb" -o "$tmp/x.png" --size 10
expect_fail "exists; expected a new file name" "$trivox" render "$tmp/f1/fichera.vdb" -o "$tmp/top.png"
expect_fail "expected three integers" "$trivox" render "$tmp/f1/fichera.vdb" -o "$tmp/x.png" --background 300,0,0
[ ! -e "$tmp/x.png" ]
"$trivox" render "$tmp/f1/fichera.vdb" -o "$tmp/top.png" --force --size 32,32 > /dev/null
echo "cli vdb: ok"
