#!/usr/bin/env bash
# End-to-end: `trivox inspect` and `trivox preview` on a slice folder written without trivox
# (Python + OpenImageIO writes the PNGs, ElementTree the ConfigFile.xml in the GCVF layout).
# Truths: voxel counts are numpy's count of the pixels written; the voxel volume is
# 25.4/600 * 25.4/300 * 0.027 mm^3; the preview is read back with OpenImageIO.
set -euo pipefail
source tests/cli/lib.bash "$@"

# A 40 x 24 px, 6-layer stack with three materials; prints the counts as JSON.
"$py" - "$tmp/stack" > "$tmp/truth.json" <<'PY'
import sys, os, json, numpy as np, OpenImageIO as oiio
import xml.etree.ElementTree as ET
d = sys.argv[1]; os.makedirs(d)
W, H, N = 40, 24, 6
mats = [("VeroCyan-V", (0, 137, 166, 255)), ("VeroMagenta-V", (198, 0, 88, 255)), ("VeroUltraWhite", (255, 255, 255, 255))]
counts = [0, 0, 0]
for k in range(N):
    a = np.zeros((H, W, 4), np.uint8)
    a[2:10, 1:5 + 4 * k] = mats[0][1]
    a[12:20, 20:36] = mats[1][1]
    a[22, 0:k + 1] = mats[2][1]
    for i, (_, c) in enumerate(mats):
        counts[i] += int(np.all(a == c, axis=2).sum())
    name = os.path.join(d, "slice_%05d.png" % k)
    spec = oiio.ImageSpec(W, H, 4, "uint8")
    spec.attribute("oiio:UnassociatedAlpha", 1)
    spec.attribute("ResolutionUnit", "inch"); spec.attribute("XResolution", 600.0); spec.attribute("YResolution", 300.0)
    out = oiio.ImageOutput.create(name)
    assert out.open(name, spec) and out.write_image(a) and out.close()
g = ET.Element("GCVF")
ET.SubElement(g, "Version").text = "2"
r = ET.SubElement(g, "Resolution")
for t, v in (("XDpi", "600"), ("YDpi", "300"), ("SliceThicknessNanoMeter", "27000")):
    ET.SubElement(r, t).text = v
sd = ET.SubElement(g, "SliceDimensions")
ET.SubElement(sd, "SliceWidth").text = str(W); ET.SubElement(sd, "SliceHeight").text = str(H)
sr = ET.SubElement(g, "SliceRange")
ET.SubElement(sr, "StartIndex").text = "0"; ET.SubElement(sr, "NumberOfSlices").text = str(N)
ET.SubElement(g, "ImageFilePrefix").text = "slice_"
ml = ET.SubElement(g, "MaterialList")
ET.SubElement(ml, "BackGroundMaterialRGBA").text = "0 0 0 0"
for (n, c), cnt in zip(mats, counts):
    m = ET.SubElement(ml, "Material")
    ET.SubElement(m, "Name").text = n
    ET.SubElement(m, "RGBA").text = " ".join(map(str, c))
    ET.SubElement(m, "VoxelCount").text = str(cnt)
ET.ElementTree(g).write(os.path.join(d, "ConfigFile.xml"), encoding="UTF-8", xml_declaration=True)
json.dump({"counts": counts, "void": W * H * N - sum(counts)}, sys.stdout)
PY

# A valid stack: exit 0, counts and volumes as written.
"$trivox" inspect "$tmp/stack" --json > "$tmp/inspect.json"
"$py" - "$tmp/inspect.json" "$tmp/truth.json" <<'PY'
import json, sys
r, t = json.load(open(sys.argv[1])), json.load(open(sys.argv[2]))
voxel = 25.4 / 600 * 25.4 / 300 * 0.027
assert r["valid"] is True and r["present"] == 6 and r["missing"] == [] and r["corrupt"] == [], r
assert r["config"]["width"] == 40 and r["config"]["height"] == 24 and r["config"]["slices"] == 6
assert r["config"]["dpi"] == [600, 300] and r["config"]["slice_thickness_nm"] == 27000
assert [m["name"] for m in r["materials"]] == ["VeroCyan-V", "VeroMagenta-V", "VeroUltraWhite"]
assert [m["voxels"] for m in r["materials"]] == t["counts"], (r["materials"], t)
assert r["void_voxels"] == t["void"]
assert abs(r["voxel_volume_mm3"] - voxel) < 1e-18
for m, n in zip(r["materials"], t["counts"]):
    assert abs(m["volume_mm3"] - n * voxel) < 1e-12 * max(1, n * voxel), m
assert abs(r["volume_mm3"] - sum(t["counts"]) * voxel) < 1e-12
PY
"$trivox" inspect "$tmp/stack" > "$tmp/inspect.txt"
grep -q "present: 6 of 6" "$tmp/inspect.txt"
grep -q "^VeroMagenta-V .* 768 " "$tmp/inspect.txt"
grep -q "stack is valid" "$tmp/inspect.txt"

# Preview: an opaque PNG of the reported size with the materials' colours; the cross-section
# in physical proportion (40 px at 600 dpi = 1.6933 mm wide, 6 x 27 um = 0.162 mm tall).
"$trivox" preview "$tmp/stack" -o "$tmp/preview.png" --json > "$tmp/preview.json"
"$trivox" preview "$tmp/stack" -o "$tmp/preview2.png" --every 2 --width 400 | grep -q "contact sheet: 3 slices from 0, step 2"
"$py" - "$tmp/preview.png" "$tmp/preview.json" "$tmp/preview2.png" <<'PY'
import json, sys, numpy as np, OpenImageIO as oiio
s = json.load(open(sys.argv[2]))
img = oiio.ImageInput.open(sys.argv[1])
a = img.read_image(format="uint8"); img.close()
assert a.shape == (s["height"], s["width"], 4) and s["width"] == 1600, (a.shape, s)
assert (a[:, :, 3] == 255).all()
px = a.reshape(-1, 4)
for c in ((0, 137, 166), (198, 0, 88), (255, 255, 255)):
    assert np.all(px[:, :3] == c, axis=1).any(), c
assert s["every"] == 1 and s["shown"] == [0, 1, 2, 3, 4, 5] and s["unreadable"] == []
sec = s["section"]
assert sec["z_scale"] == 1 and abs(sec["height"] - sec["width"] * 0.162 / (40 * 25.4 / 600)) <= 1, sec
b = oiio.ImageInput.open(sys.argv[3]); assert b.spec().width == 400; b.close()
PY
ls -A "$tmp" | grep -q '\.tmp' && { echo "temporary files left behind"; ls -A "$tmp"; exit 1; }

# Broken stack: slice 2 truncated, slice 4 missing, slice 3 with a foreign colour:
# the report still prints (stdout), then exit 1 with the reason on stderr.
cp -r "$tmp/stack" "$tmp/broken"
"$py" - "$tmp/broken" <<'PY'
import sys, os, numpy as np, OpenImageIO as oiio
d = sys.argv[1]
p = os.path.join(d, "slice_00002.png"); b = open(p, "rb").read(); open(p, "wb").write(b[: len(b) // 2])
os.remove(os.path.join(d, "slice_00004.png"))
p = os.path.join(d, "slice_00003.png")
i = oiio.ImageInput.open(p, oiio.ImageSpec()); a = i.read_image(format="uint8"); i.close()
a[5, 9] = (255, 0, 0, 255)
o = oiio.ImageOutput.create(p); o.open(p, oiio.ImageSpec(40, 24, 4, "uint8")); o.write_image(a); o.close()
PY
set +e
"$trivox" inspect "$tmp/broken" --json > "$tmp/broken.json" 2> "$tmp/broken.err"
rc=$?
set -e
[ $rc -eq 1 ] || { echo "expected exit 1 for a broken stack, got $rc"; cat "$tmp/broken.err"; exit 1; }
grep -q "invalid stack: 1 missing, 2 corrupt" "$tmp/broken.err" || { cat "$tmp/broken.err"; exit 1; }
"$py" - "$tmp/broken.json" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
assert r["valid"] is False and r["missing"] == [4] and r["corrupt"] == [2, 3] and r["present"] == 5, r
reasons = {p["index"]: p["reason"] for p in r["problems"]}
assert "truncated" in reasons[2] and "foreign" in reasons[3] and "255 0 0 255" in reasons[3] and reasons[4] == "missing", reasons
PY
set +e
"$trivox" inspect "$tmp/broken" > "$tmp/broken.txt" 2> /dev/null
set -e
grep -q "slice_00002.png: truncated" "$tmp/broken.txt"
grep -q "stack is INVALID" "$tmp/broken.txt"
# preview still draws it, crossing out what it cannot read.
"$trivox" preview "$tmp/broken" -o "$tmp/broken.png" --json > "$tmp/bp.json"
"$py" -c "import json,sys; s=json.load(open(sys.argv[1])); assert s['unreadable']==[2,4], s" "$tmp/bp.json"
# With every third slice on the sheet (0, 3), the section's red rows still name 2 and 4.
"$trivox" preview "$tmp/broken" -o "$tmp/broken3.png" --every 3 --json > "$tmp/bp3.json"
"$py" -c "import json,sys; s=json.load(open(sys.argv[1])); assert s['shown']==[0,3] and s['unreadable']==[2,4], s" "$tmp/bp3.json"

# A recorded VoxelCount that the pixels contradict: exit 1.
cp -r "$tmp/stack" "$tmp/miscount"
sed -i 's|<VoxelCount>768</VoxelCount>|<VoxelCount>769</VoxelCount>|' "$tmp/miscount/ConfigFile.xml"
set +e
"$trivox" inspect "$tmp/miscount" > /dev/null 2> "$tmp/err"; rc=$?
set -e
[ $rc -eq 1 ] && grep -q "VoxelCount mismatch" "$tmp/err"

# Bad input: exit 2, a message naming the file, the place and what was expected; no stdout.
mkdir "$tmp/empty"
expect_fail "no ConfigFile.xml; expected a slice folder" "$trivox" inspect "$tmp/empty"
expect_fail "no such folder" "$trivox" inspect "$tmp/nothing"
expect_fail "is a file; expected a slice folder" "$trivox" inspect "$tmp/truth.json"
cp -r "$tmp/stack" "$tmp/badxml"
sed -i 's|<XDpi>600</XDpi>|<XDpi>six hundred</XDpi>|' "$tmp/badxml/ConfigFile.xml"
expect_fail "ConfigFile.xml: GCVF/Resolution/XDpi (line 2): \"six hundred\" is not a number; expected" "$trivox" inspect "$tmp/badxml"
head -c 200 "$tmp/stack/ConfigFile.xml" > "$tmp/badxml/ConfigFile.xml"
expect_fail "ConfigFile.xml: line 2, column" "$trivox" inspect "$tmp/badxml"
expect_fail "no ConfigFile.xml" "$trivox" preview "$tmp/empty" -o "$tmp/x.png"
expect_fail "expected 64..16384" "$trivox" preview "$tmp/stack" -o "$tmp/x.png" --width 10
expect_fail "" "$trivox" preview "$tmp/stack"
expect_fail "expected an existing, writable folder" "$trivox" preview "$tmp/stack" -o "$tmp/no/such/dir/x.png"
[ ! -e "$tmp/x.png" ]
echo "cli inspect/preview: ok"
