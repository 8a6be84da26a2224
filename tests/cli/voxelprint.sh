#!/usr/bin/env bash
# Voxel Print stacks as the public tools take them (docs/slice-output.md): read back by
# voxelprint_reader.py, the logic of the public reader voxelprint-preview written again in Python
# (its own PNG decoder, checked first against OpenImageIO on libpng's filtered rows).
# Truths: the reader's per-material counts equal ConfigFile.xml's VoxelCount and `trivox
# inspect`'s, for unpadded and padded names, a zipped .gcvf, a transparent and a black void; the
# same model gives the same pixels whatever the names; refusals exit 2 naming what was expected;
# an earlier trivox's padded stack still resumes and merges to the same bytes.
# The .gcvf's Mesh.stl, read by Python's zipfile and an STL parser written here: every edge in
# exactly two facets, in opposite directions; its enclosed volume is the graded block's 9600 and a
# plate less a cylinder's 4 - pi/4 within tolerance x area, and `trivox mesh`'s; the archive is
# byte-identical for 1 and 2 threads and for 2 shards merged; a model that cannot be meshed gets
# its archive without the mesh, a warning on stderr and in --json, exit 0.
set -euo pipefail
source tests/cli/lib.bash "$@"

model=models/graded_block.json
grid=(--dpi 100,100 --layer 0.5 --progress never --threads 2)    # 158 x 79 pixels, 88 layers

# 0. The reader's PNG decoder, against OpenImageIO on PNGs whose rows use every one of the five
#    row filters (trivox writes filter 0 only; a reader must take all five). The files are
#    filtered here, after the PNG specification, so each filter is certain to be used.
"$py" - "$tmp/filtered.png" <<'PY'
import sys, struct, zlib
import numpy as np
import OpenImageIO as oiio
sys.path.insert(0, "tests/cli")
from voxelprint_reader import decode_png, row_filters
path = sys.argv[1]

def paeth(a, b, c):
    p = a + b - c
    pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
    return a if pa <= pb and pa <= pc else (b if pb <= pc else c)

def encode(img):  # row y with filter y % 5
    h, w, ch = img.shape
    rows, prev = [], [0] * (w * ch)
    for y in range(h):
        cur, f, out = [int(v) for v in img[y].reshape(-1)], y % 5, []
        for x, v in enumerate(cur):
            a = cur[x - ch] if x >= ch else 0
            b, c = prev[x], (prev[x - ch] if x >= ch else 0)
            pred = [0, a, b, (a + b) // 2, paeth(a, b, c)][f]
            out.append((v - pred) & 255)
        rows.append(bytes([f] + out))
        prev = cur
    chunk = lambda k, d: struct.pack(">I", len(d)) + k + d + struct.pack(">I", zlib.crc32(k + d))
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 6 if ch == 4 else 2, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(b"".join(rows))) + chunk(b"IEND", b""))

h, w = 23, 37
y, x = np.mgrid[0:h, 0:w]
rgb = np.stack([(3 * x + y) % 256, (x * y) % 251, (7 * y) % 256], axis=2).astype(np.uint8)
for img in [np.concatenate([rgb, ((x * 13 + y) % 256)[..., None].astype(np.uint8)], axis=2), rgb]:
    data = encode(img)
    open(path, "wb").write(data)
    assert sorted(set(row_filters(data))) == [0, 1, 2, 3, 4]
    config = oiio.ImageSpec()
    config.attribute("oiio:UnassociatedAlpha", 1)    # colours as stored, not premultiplied
    inp = oiio.ImageInput.open(path, config)
    ref = inp.read_image(format="uint8")
    inp.close()
    assert (ref == img).all()
    got = decode_png(data, path)
    assert (got[..., :img.shape[2]] == img).all() and (img.shape[2] == 4 or (got[..., 3] == 255).all())
PY

# 1. Four stacks of one model: unpadded names and transparent void (the defaults) with a .gcvf,
#    zero-padded names, black void with a .gcvf, and the J850's seven channels.
"$trivox" slice $model -o "$tmp/u" "${grid[@]}" --zip --json > "$tmp/u.json"
"$trivox" slice $model -o "$tmp/p" "${grid[@]}" --digits 5 > /dev/null
"$trivox" slice $model -o "$tmp/b" "${grid[@]}" --background black --zip > /dev/null
"$trivox" slice $model -o "$tmp/j" "${grid[@]}" --printer j850 > /dev/null
for s in u u.gcvf p b b.gcvf j; do
  "$py" tests/cli/voxelprint_reader.py "$tmp/$s" > "$tmp/read-$s.json"
done
for s in u p b j; do "$trivox" inspect "$tmp/$s" --json > "$tmp/inspect-$s.json"; done
"$py" - "$tmp" <<'PY'
import sys, os, json
t = sys.argv[1]
read = {s: json.load(open(os.path.join(t, f"read-{s}.json"))) for s in ["u", "u.gcvf", "p", "b", "b.gcvf", "j"]}
summary = json.load(open(os.path.join(t, "u.json")))
for s, r in read.items():
    c = r["config"]
    # The counts the reader finds are those ConfigFile.xml records and trivox inspect reports.
    recorded = {m["name"]: m["voxelCount"] for m in c["MaterialList"]}
    assert r["counts"] == recorded, (s, r["counts"], recorded)
    ins = json.load(open(os.path.join(t, f"inspect-{s.split('.')[0]}.json")))
    assert ins["valid"], s
    assert {m["name"]: m["voxels"] for m in ins["materials"]} == r["counts"], s
    assert ins["void_voxels"] == r["void"], s
    # The materials listed are the ones used; numbers are the integers every reader parses.
    assert all(v > 0 for v in recorded.values()) and len(recorded) == 5, (s, recorded)
    assert (c["XDpi"], c["YDpi"], c["SliceThicknessNanoMeter"]) == (100, 100, 500000), s
    assert c["MaxNumberOfColors"] == (7 if s == "j" else 6), s
    assert sum(r["counts"].values()) + r["void"] == 158 * 79 * 88, s
    # The job's own summary agrees.
    assert {m["name"]: m["voxels"] for m in summary["materials"] if m["voxels"]} == r["counts"], s
# Every stack holds the same voxels; only the void colour differs.
for s in read:
    assert read[s]["counts"] == read["u"]["counts"] and read[s]["void"] == read["u"]["void"], s
assert read["b"]["config"]["Background"] == [0, 0, 0, 255] and read["u"]["config"]["Background"] == [0, 0, 0, 0]
assert read["b"]["pixels"]["0 0 0 255"] == read["b"]["void"] and "0 0 0 0" not in read["b"]["pixels"]
assert read["u"]["pixels"]["0 0 0 0"] == read["u"]["void"] and "0 0 0 255" not in read["u"]["pixels"]
# Names: unpadded by default, padded with --digits 5; the .gcvf holds the folder's names.
names = lambda d: sorted(f for f in os.listdir(os.path.join(t, d)) if f.endswith(".png"))
assert names("u") == sorted(f"slice_{k}.png" for k in range(88)), names("u")[:5]
assert names("p") == [f"slice_{k:05d}.png" for k in range(88)], names("p")[:5]
import zipfile
z = zipfile.ZipFile(os.path.join(t, "u.gcvf"))
# ConfigFile.xml, the slices, then the boundary mesh, as the public archives hold it.
assert z.namelist() == ["ConfigFile.xml"] + [f"slice_{k}.png" for k in range(88)] + ["Mesh.stl"], z.namelist()[:4]
PY
for k in 0 7 42 87; do cmp "$tmp/u/slice_$k.png" "$tmp/p/slice_$(printf %05d $k).png"; done
cmp "$tmp/u/ConfigFile.xml" "$tmp/p/ConfigFile.xml"    # the names are not in it
# inspect and preview take both forms of names.
"$trivox" preview "$tmp/u" -o "$tmp/u-preview.png" > /dev/null
"$trivox" preview "$tmp/p" -o "$tmp/p-preview.png" > /dev/null
cmp "$tmp/u-preview.png" "$tmp/p-preview.png"
grep -q "slice_00000.png .. slice_00087.png" <("$trivox" inspect "$tmp/p")
grep -q "void: black (0 0 0 255); MaxNumberOfColors 6" <("$trivox" inspect "$tmp/b")

# 2. What a reader would misread, or a printer cannot hold, is refused before anything is written.
expect_exit 2 "--dpi 600.5,300: not whole dots per inch; expected integers" "$tmp/x1" \
  "$trivox" slice $model -o "$tmp/x1" --dpi 600.5,300
expect_exit 2 "--layer 0.0270005: 27000.5 nm, not a whole number of nanometres" "$tmp/x2" \
  "$trivox" slice $model -o "$tmp/x2" --layer 0.0270005
expect_exit 2 "--background white: unknown; expected transparent or black" "$tmp/x3" \
  "$trivox" slice $model -o "$tmp/x3" --background white
expect_exit 2 "--digits 10: out of range; expected 0 (no padding: slice_7.png) to 9" "$tmp/x4" \
  "$trivox" slice $model -o "$tmp/x4" --digits 10
expect_fail "--digits: applies to the PNG stack" "$trivox" slice $model -o "$tmp/x5" --vdb --digits 3
"$py" - "$tmp" <<'PY'
import sys, json
t = sys.argv[1]
p = json.load(open("models/palettes/vero.json"))
black = dict(p, name="pure-black", materials=[dict(m, rgba=[0, 0, 0, 255]) if m["name"] == "VeroBlack" else m for m in p["materials"]])
json.dump(black, open(t + "/black.json", "w"))
seven = dict(p, name="seven", materials=p["materials"] + [{"name": "Agilus30", "rgba": [200, 160, 120, 255]}])
json.dump(seven, open(t + "/seven.json", "w"))
PY
expect_exit 2 "material VeroBlack is coloured 0 0 0 255, the void colour of --background black" "$tmp/x6" \
  "$trivox" slice $model -o "$tmp/x6" "${grid[@]}" --background black --palette "$tmp/black.json"
"$trivox" slice $model -o "$tmp/x7" "${grid[@]}" --palette "$tmp/black.json" > /dev/null    # transparent void: fine
expect_exit 2 "seven.json: 7 materials (VeroCyan-V, VeroMagenta-V, VeroYellow-V, VeroBlack, VeroUltraWhite, UltraClear, Agilus30); the j750 holds 6 at once" "$tmp/x8" \
  "$trivox" slice $model -o "$tmp/x8" --printer j750 --palette "$tmp/seven.json"
"$trivox" slice $model -o "$tmp/x9" "${grid[@]}" --printer j850 --palette "$tmp/seven.json" > /dev/null

# 3. An earlier trivox's stack: padded names, a manifest without png.digits and png.background.
#    --resume without --digits continues it under its own names; shards merge to the same bytes.
cp -r "$tmp/p" "$tmp/old"
"$py" - "$tmp/old/manifest.json" <<'PY'
import sys, json
path = sys.argv[1]
m = json.load(open(path))
for k in ["png.digits", "png.background", "png.channels"]:
    del m["options"][k]
m["layers"] = [l for l in m["layers"] if l["index"] % 3]           # a third of the layers unlisted
m["complete"] = False
open(path, "w").write(json.dumps(m, indent=2) + "\n")
PY
rm "$tmp/old/slice_00003.png" "$tmp/old/ConfigFile.xml"
"$trivox" slice $model -o "$tmp/old" "${grid[@]}" --resume > "$tmp/resume.txt"
grep -q "resumed: 58 layers kept" "$tmp/resume.txt"
for f in "$tmp"/p/*; do cmp "$f" "$tmp/old/$(basename "$f")"; done
[ "$(ls "$tmp/old" | wc -l)" -eq "$(ls "$tmp/p" | wc -l)" ]
"$trivox" slice $model -o "$tmp/sh" "${grid[@]}" --digits 5 --shard 0/2 > /dev/null
"$trivox" slice $model -o "$tmp/sh" "${grid[@]}" --digits 5 --shard 1/2 > /dev/null
"$trivox" merge "$tmp/sh" > /dev/null
for f in "$tmp"/p/*; do cmp "$f" "$tmp/sh/$(basename "$f")"; done

# 4. The archive's boundary mesh (docs/slice-output.md, "The .gcvf file").
cat > "$tmp/post_scene.json" <<'EOF2'
{ "trivox": 1, "units": "mm", "properties": ["r", "g", "b"],
  "cells": [
    { "name": "plate", "primitive": {"type": "box", "min": [-1, -1, 0], "max": [1, 1, 1]}, "field": {"constant": [0.3, 0.3, 0.3]} },
    { "name": "post", "primitive": {"type": "cylinder", "base": [0, 0, -1], "axis": [0, 0, 1], "radius": 0.5, "height": 3}, "field": {"constant": [0.6, 0.6, 0.6]} }
  ],
  "operations": [ {"op": "subtraction", "a": "plate", "b": "post"} ] }
EOF2
"$trivox" build "$tmp/post_scene.json" -o "$tmp/post.json" > /dev/null
fine=(--dpi 300,300 --layer 0.1 --progress never)
"$trivox" slice "$tmp/post.json" -o "$tmp/post1" "${fine[@]}" --threads 1 --zip --json > "$tmp/post1.json"
"$trivox" slice "$tmp/post.json" -o "$tmp/post2" "${fine[@]}" --threads 2 --zip > /dev/null
cmp "$tmp/post1.gcvf" "$tmp/post2.gcvf"
"$trivox" mesh "$tmp/post.json" -o "$tmp/post.stl" --json > "$tmp/post_mesh.json"
"$trivox" mesh $model -o "$tmp/block.stl" --json > "$tmp/block_mesh.json"
"$trivox" slice $model -o "$tmp/u1" --dpi 100,100 --layer 0.5 --progress never --threads 1 --zip > /dev/null
cmp "$tmp/u.gcvf" "$tmp/u1.gcvf"
"$trivox" slice $model -o "$tmp/zs" "${grid[@]}" --zip --shard 1/2 > /dev/null
"$trivox" slice $model -o "$tmp/zs" "${grid[@]}" --zip --shard 0/2 > /dev/null
"$trivox" merge "$tmp/zs" > /dev/null
cmp "$tmp/u.gcvf" "$tmp/zs.gcvf"
"$py" - "$tmp" <<'PY'
import sys, os, json, math, struct, zipfile, hashlib
from collections import Counter
t = sys.argv[1]

def read_stl(data):
    """A binary STL: an 80-byte header, a little-endian uint32 count, 50 bytes a facet."""
    assert len(data) >= 84 and not data.startswith(b"solid"), data[:80]
    n, = struct.unpack_from("<I", data, 80)
    assert len(data) == 84 + 50 * n, (len(data), n)
    facets = []
    for i in range(n):
        f = struct.unpack_from("<12fH", data, 84 + 50 * i)
        assert f[12] == 0
        facets.append((f[3:6], f[6:9], f[9:12]))
    return facets

def check_closed(facets):
    """Every edge in exactly two facets, once in each direction (vertices matched by their bits)."""
    directed = Counter()
    for a, b, c in facets:
        assert len({a, b, c}) == 3, (a, b, c)
        for p, q in ((a, b), (b, c), (c, a)):
            directed[(p, q)] += 1
    for (p, q), k in directed.items():
        assert k == 1 and directed[(q, p)] == 1, (p, q, k)

def volume(facets):
    o = [sum(v[i] for f in facets for v in f) / (3 * len(facets)) for i in range(3)]
    s = 0.0
    for f in facets:
        a, b, c = ([v[i] - o[i] for i in range(3)] for v in f)
        s += (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) + a[2] * (b[0] * c[1] - b[1] * c[0])) / 6
    return s

# The graded block: the box 40 x 20 x 10 and the arch (x = 40 u, y = 5 + 10 w, z = z(u) + 4 v:
# det J = 40 x 10 x 4 over the unit cube), 8000 + 1600.
for name, exact, mesh_json, stl in [("u", 9600.0, "block_mesh.json", "block.stl"), ("post1", 4 - math.pi / 4, "post_mesh.json", "post.stl")]:
    z = zipfile.ZipFile(os.path.join(t, name + ".gcvf"))
    assert z.namelist()[-1] == "Mesh.stl" and z.namelist()[0] == "ConfigFile.xml", z.namelist()[-2:]
    assert b"Mesh" not in z.read("ConfigFile.xml")     # the format does not name it
    data = z.read("Mesh.stl")
    assert data == open(os.path.join(t, name, "Mesh.stl"), "rb").read()
    assert data[80:] == open(os.path.join(t, stl), "rb").read()[80:]    # trivox mesh's triangles
    facets = read_stl(data)
    check_closed(facets)
    v, m = volume(facets), json.load(open(os.path.join(t, mesh_json)))
    assert abs(v - m["volume"]) <= 1e-5 * exact, (name, v, m["volume"])
    # The triangles lie within the tolerance of the surface: the volume within tolerance x area.
    assert abs(v - exact) <= m["tolerance"] * m["area"] + 1e-5 * exact, (name, v, exact, m["tolerance"])
    # The manifest lists it with its SHA-256, as it lists the other outputs.
    man = json.load(open(os.path.join(t, name, "manifest.json")))
    files = {f["role"]: f for f in man["files"]}
    assert files["mesh"] == {"role": "mesh", "file": "Mesh.stl", "sha256": hashlib.sha256(data).hexdigest()}, files
s = json.load(open(os.path.join(t, "post1.json")))
assert s["mesh"].endswith("post1/Mesh.stl") and s["mesh_warning"] is None, s
PY

# The quick start's wall stands on part of its plate's top, which the mesher refuses (docs/mesh.md):
# the archive is written without a mesh, with a warning.
"$trivox" build models/quickstart.json -o "$tmp/quick.json" > /dev/null
"$trivox" slice "$tmp/quick.json" -o "$tmp/quick" "${grid[@]}" --zip --json > "$tmp/quick.out" 2> "$tmp/quick.err"
grep -q "trivox: warning: .*no Mesh.stl in the archive: .*glued to cell .* over part of its area only" "$tmp/quick.err"
"$py" - "$tmp" <<'PY'
import sys, os, json, zipfile
t = sys.argv[1]
s = json.load(open(os.path.join(t, "quick.out")))
assert s["mesh"] is None and "over part of its area only" in s["mesh_warning"], s
names = zipfile.ZipFile(os.path.join(t, "quick.gcvf")).namelist()
assert "Mesh.stl" not in names and names[0] == "ConfigFile.xml" and len(names) > 1, names
assert not os.path.exists(os.path.join(t, "quick", "Mesh.stl"))
assert "mesh" not in {f["role"] for f in json.load(open(os.path.join(t, "quick", "manifest.json")))["files"]}
PY
echo "voxelprint: ok"
