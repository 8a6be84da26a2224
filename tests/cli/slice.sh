#!/usr/bin/env bash
# End-to-end: `trivox slice` writes a Voxel Print stack that independent readers (OpenImageIO's
# Python module, Python's XML parser) agree with.
# Truth: the Fichera corner [-1,1]^3 minus the positive octant at pitch 0.254 mm (100 dpi, 0.254 mm
# layers) has 8 voxel centres per axis at -1 + (i + 1/2) 0.254, none on a face: 8^3 - 4^3 = 448
# voxels inside.
set -euo pipefail
source tests/cli/lib.bash "$@"

"$trivox" slice models/gismo/fichera.xml -o "$tmp/f1" --dpi 100,100 --layer 0.254 --threads 1 --progress never --json > "$tmp/f1.json"
"$trivox" slice models/gismo/fichera.xml -o "$tmp/f2" --dpi 100,100 --layer 0.254 --threads 2 --progress never > /dev/null
for f in "$tmp"/f1/*; do cmp "$f" "$tmp/f2/$(basename "$f")"; done   # identical for 1 and 2 threads
[ "$(ls "$tmp/f1" | wc -l)" -eq "$(ls "$tmp/f2" | wc -l)" ]

# A colour model takes the grouped dither (several layers per vector, LayerGroupDitherer): the
# stack is the same with 1 and 2 threads and with every group cut to one layer (the single-layer
# kernel), group sizes 3 and 5 (other lane fillings), a layer range that splits the groups, and
# without the AVX-512 kernels (the sampler's property samples and the dither in AVX2 registers;
# the same as the rest on a CPU without AVX-512).
col=(--dpi 300,150 --layer 0.1 --progress never)
"$trivox" slice models/twisted_column.json -o "$tmp/c8" "${col[@]}" --threads 2 > /dev/null
"$trivox" slice models/twisted_column.json -o "$tmp/c8t1" "${col[@]}" --threads 1 > /dev/null
TRIVOX_LAYER_GROUP=1 "$trivox" slice models/twisted_column.json -o "$tmp/c1" "${col[@]}" --threads 2 > /dev/null
TRIVOX_LAYER_GROUP=3 "$trivox" slice models/twisted_column.json -o "$tmp/c3" "${col[@]}" --threads 2 > /dev/null
TRIVOX_LAYER_GROUP=5 "$trivox" slice models/twisted_column.json -o "$tmp/c5" "${col[@]}" --threads 1 > /dev/null
TRIVOX_NO_AVX512=1 "$trivox" slice models/twisted_column.json -o "$tmp/c2" "${col[@]}" --threads 2 > /dev/null
"$trivox" slice models/twisted_column.json -o "$tmp/cs" "${col[@]}" --threads 2 --shard 1/3 > /dev/null
[ "$(ls "$tmp/c8"/slice_*.png | wc -l)" -gt 20 ]
# 0.1 mm layers: the thickness in plain decimal (1e+05 once), as integer readers want it.
grep -q "<SliceThicknessNanoMeter>100000</SliceThicknessNanoMeter>" "$tmp/c8/ConfigFile.xml"
for d in c8t1 c1 c3 c5 c2; do
  for f in "$tmp"/c8/slice_*.png "$tmp/c8/ConfigFile.xml"; do cmp "$f" "$tmp/$d/$(basename "$f")"; done
done
[ "$(ls "$tmp/cs"/slice_*.png | wc -l)" -gt 5 ]
for f in "$tmp"/cs/slice_*.png; do cmp "$f" "$tmp/c8/$(basename "$f")"; done

"$py" - "$tmp/f1" "$tmp/f1.json" <<'PY'
import sys, os, json, glob
import xml.etree.ElementTree as ET
import OpenImageIO as oiio
d, summary = sys.argv[1], json.load(open(sys.argv[2]))
root = ET.parse(os.path.join(d, "ConfigFile.xml")).getroot()
def find(tag):
    e = root.find(".//" + tag)
    assert e is not None, tag
    return e.text.strip()
w, h, n = int(find("SliceWidth")), int(find("SliceHeight")), int(find("NumberOfSlices"))
assert (w, h, n) == (8, 8, 8), (w, h, n)
prefix = find("ImageFilePrefix")
slices = sorted(glob.glob(os.path.join(d, prefix + "*.png")))
assert len(slices) == n, slices
palette = {}
for m in root.iter("Material"):
    name = m.find("Name").text.strip()
    rgba = tuple(int(x) for x in m.find("RGBA").text.split())
    palette[rgba] = [name, int(m.find("VoxelCount").text), 0]
filled = 0
for path in slices:
    inp = oiio.ImageInput.open(path)
    spec = inp.spec()
    assert (spec.width, spec.height, spec.nchannels) == (w, h, 4), path
    assert abs(spec.get_float_attribute("XResolution") - 100) < 1e-3, spec.get_float_attribute("XResolution")  # pHYs holds pixels per metre
    px = inp.read_image(format="uint8")
    inp.close()
    for row in px:
        for p in row:
            p = tuple(int(c) for c in p)
            if p[3] == 0:
                continue
            assert p in palette, p
            palette[p][2] += 1
            filled += 1
assert filled == 448, filled
for rgba, (name, cfg_count, seen) in palette.items():
    assert cfg_count == seen, (name, cfg_count, seen)
assert summary["filled"] == 448 and summary["inversion_failures"] == 0, summary
PY

# The J850 preset: 600 x 300 dpi and 27 um layers, as the J750's; --progress lines reports the
# first layer (ETA not yet known) and the last, on stderr, beside a JSON summary on stdout.
"$trivox" slice models/gismo/fichera.xml -o "$tmp/j850" --printer j850 --progress lines --json > "$tmp/j850.json" 2> "$tmp/j850.err"
"$py" - "$tmp/j850.json" <<'PY'
import sys, json
s = json.load(open(sys.argv[1]))
assert s["printer"] == "j850" and s["dpi"] == [600, 300] and s["layer_mm"] == 0.027, s
assert s["grid"]["pitch"] == [25.4 / 600, 25.4 / 300, 0.027] and s["grid"]["count"] == [48, 24, 75], s["grid"]
PY
grep -q "trivox slice: 1/75 layers, .* ETA --" "$tmp/j850.err"
grep -q "trivox slice: 75/75 layers" "$tmp/j850.err"
"$trivox" slice models/gismo/fichera.xml -o "$tmp/quiet" --dpi 100,100 --progress never 2> "$tmp/quiet.err" > /dev/null
[ ! -s "$tmp/quiet.err" ]

# Refusals: exit 2 with the reason.
# A model wider than the tray (a 500 mm box; the J750's tray is 490 x 390 x 200 mm), with the job's size.
"$py" -c "
import json, sys
pts = [[500 * x, 10 * y, 10 * z] for z in (0, 1) for y in (0, 1) for x in (0, 1)]
json.dump({'trivox': 1, 'units': 'mm', 'properties': [], 'cells': [{'name': 'bar', 'trivariate': {
    'orders': [2, 2, 2], 'knots': [[0, 0, 1, 1]] * 3, 'points': pts}}]}, open(sys.argv[1], 'w'))" "$tmp/bar.json"
expect_exit 2 "bar.json: the model is 500 mm along x, larger than the j750 tray (490 mm); expected a model that fits (or --force). Job: 11812 x 119 x 371" "$tmp/x12" "$trivox" slice "$tmp/bar.json" -o "$tmp/x12"
expect_fail "not empty" "$trivox" slice models/gismo/fichera.xml -o "$tmp/f1" --dpi 100,100 --layer 0.254 --progress never
expect_fail "unknown printer" "$trivox" slice models/gismo/fichera.xml -o "$tmp/x1" --printer j9000
expect_fail "--dpi 0,100: out of range; expected 10 to 10000" "$trivox" slice models/gismo/fichera.xml -o "$tmp/x2" --dpi 0,100
expect_fail "--layer -1: out of range; expected a layer" "$trivox" slice models/gismo/fichera.xml -o "$tmp/x3" --layer -1
expect_fail "expected fs, stochastic or none" "$trivox" slice models/gismo/fichera.xml -o "$tmp/x4" --dither blue
expect_fail "voxels" "$trivox" slice models/gismo/fichera.xml -o "$tmp/x5" --max-voxels 100
echo '{"materials": 3}' > "$tmp/bad-palette.json"
expect_fail "bad-palette.json" "$trivox" slice models/gismo/fichera.xml -o "$tmp/x6" --palette "$tmp/bad-palette.json"
expect_fail "teapot.xml: no cells; expected" "$trivox" slice models/gismo/teapot.xml -o "$tmp/x7"
# A well-formed palette that lacks the colour materials an r, g, b model needs: its file is named.
echo '{"trivox_palette": 1, "materials": [{"name": "A", "rgba": [1, 2, 3]}]}' > "$tmp/mono.json"
expect_fail "mono.json: .*the palette lacks VeroCyan-V" "$trivox" slice models/twisted_column.json -o "$tmp/x8" --palette "$tmp/mono.json"
# Option values CLI11 cannot convert, and values out of range, in trivox's words.
expect_fail "trivox: error: --layer abc: not a number; expected a number" "$trivox" slice models/gismo/fichera.xml -o "$tmp/x9" --layer abc
expect_fail "trivox: error: --threads 1.5: not a whole number" "$trivox" slice models/gismo/fichera.xml -o "$tmp/x9" --threads 1.5
expect_fail "trivox: error: --max-voxels -5: out of range; expected a whole number of voxels" "$trivox" slice models/gismo/fichera.xml -o "$tmp/x9" --max-voxels -5
expect_fail "trivox: error: --output is required; see trivox slice --help" "$trivox" slice models/gismo/fichera.xml
expect_fail "trivox: error: slise: unknown command; expected one of info, eval" "$trivox" slise models/gismo/fichera.xml
# --max-voxels as the help writes its default: 1e3 is a thousand.
expect_fail "expected at most 1000 voxels" "$trivox" slice models/gismo/fichera.xml -o "$tmp/x9" --dpi 100,100 --max-voxels 1e3
# A model without volume (every point on the plane z = 0) is refused, not sliced to nothing.
"$py" -c "
import json, sys
pts = [[x, y, 0] for z in (0, 1) for y in (0, 1) for x in (0, 1)]
json.dump({'trivox': 1, 'units': 'mm', 'properties': [], 'cells': [{'name': 'p', 'trivariate': {
    'orders': [2, 2, 2], 'knots': [[0, 0, 1, 1]] * 3, 'points': pts}}]}, open(sys.argv[1], 'w'))" "$tmp/flat.json"
expect_exit 2 "flat.json: the model's box is 0 mm along z" "$tmp/x10" "$trivox" slice "$tmp/flat.json" -o "$tmp/x10"
expect_exit 2 "flat.json: the model's box is 0 mm along z" "$tmp/x10" "$trivox" slice "$tmp/flat.json" -o "$tmp/x10" --vdb
# --zip: the archive's place is checked before any slice is written; an archive there is kept
# unless --force.
mkdir -p "$tmp/x11.gcvf/sub"
expect_exit 2 "x11.gcvf: is a folder; expected a .gcvf file" "$tmp/x11" "$trivox" slice models/gismo/fichera.xml -o "$tmp/x11" --zip
rm -r "$tmp/x11.gcvf"; echo precious > "$tmp/x11.gcvf"
expect_exit 2 "x11.gcvf: exists; expected a new archive" "$tmp/x11" "$trivox" slice models/gismo/fichera.xml -o "$tmp/x11" --zip
[ "$(cat "$tmp/x11.gcvf")" = precious ]
"$trivox" slice models/gismo/fichera.xml -o "$tmp/x11" --dpi 100,100 --zip --force --progress never > /dev/null
unzip -l "$tmp/x11.gcvf" > "$tmp/x11.list"; grep -q ConfigFile.xml "$tmp/x11.list"
# --force overwrites.
"$trivox" slice models/gismo/fichera.xml -o "$tmp/f1" --dpi 100,100 --layer 0.254 --progress never --force > /dev/null
echo "cli slice: ok"
