"""A Voxel Print stack read the way the public reader voxelprint-preview (jackcrane) reads one,
its logic written again here, independent of trivox:

- ConfigFile.xml: each element is the first of its name anywhere in the document
  (querySelector); the resolution, size and slice range are parsed as integers (parseInt);
  a material's RGBA is its text split on single spaces, each part an integer.
- Slice i, for i from StartIndex to StartIndex + NumberOfSlices - 1, is the file
  `<ImageFilePrefix><i>.png`, or else the PNG whose name, with the prefix and ".png" taken
  out, parses as the integer i (so zero-padded names are found too). A .gcvf is a zip whose
  entries are taken by their base name.
- Each pixel is looked up by its "r g b a" key: the background key and transparent pixels
  are void, a material's key is that material; any other colour is a defect here.

The PNGs are decoded by this file too (zlib and the five PNG row filters, after the PNG
specification), not by the library trivox writes them with.

Usage: voxelprint_reader.py STACK (a folder or a .gcvf) -> prints one JSON object:
{"config": {...}, "counts": {name: voxels}, "void": n, "pixels": {"r g b a": n}}
"""
import json
import os
import re
import struct
import sys
import xml.etree.ElementTree as ET
import zipfile
import zlib

import numpy as np


def fail(msg):
    raise SystemExit("voxelprint_reader: " + msg)


def parse_int(text, what):
    """JavaScript's parseInt, held to what a writer must give it: the whole text an integer."""
    t = (text or "").strip()
    if not re.fullmatch(r"[0-9]+", t):
        fail(f"{what}: {t!r} is not an integer (parseInt would read {re.match(r'[0-9]*', t).group() or 'NaN'})")
    return int(t)


def parse_config(text):
    root = ET.fromstring(text)
    first = lambda tag: next(root.iter(tag), None)
    get = lambda tag: first(tag).text if first(tag) is not None else None
    cfg = {k: parse_int(get(k), k) for k in (
        "XDpi", "YDpi", "SliceThicknessNanoMeter", "SliceWidth", "SliceHeight", "StartIndex", "NumberOfSlices",
        "MaxNumberOfColors")}
    cfg["Version"] = (get("Version") or "").strip()
    cfg["ImageFilePrefix"] = (get("ImageFilePrefix") or "").strip() or "layer_"
    bg = first("BackGroundMaterialRGBA")
    cfg["Background"] = [parse_int(p, "BackGroundMaterialRGBA") for p in bg.text.strip().split(" ")] if bg is not None else None
    cfg["MaterialList"] = []
    for m in root.iter("Material"):
        rgba = [parse_int(p, "RGBA") for p in m.find("RGBA").text.split(" ")]
        if len(rgba) != 4:
            fail(f"RGBA {m.find('RGBA').text!r}: expected 4 integers separated by single spaces")
        cfg["MaterialList"].append({"name": m.find("Name").text, "rgba": rgba,
                                    "voxelCount": parse_int(m.find("VoxelCount").text, "VoxelCount")})
    return cfg


def paeth(a, b, c):
    p = a + b - c
    pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
    return a if pa <= pb and pa <= pc else (b if pb <= pc else c)


def decode_png(data, name):
    """8-bit RGB or RGBA, not interlaced -> (height, width, 4) uint8 array."""
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        fail(f"{name}: not a PNG")
    pos, idat, ihdr = 8, [], None
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if zlib.crc32(kind + body) != struct.unpack(">I", data[pos + 8 + length:pos + 12 + length])[0]:
            fail(f"{name}: chunk {kind!r} fails its CRC")
        if kind == b"IHDR":
            ihdr = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat.append(body)
        elif kind == b"IEND":
            break
        pos += 12 + length
    w, h, depth, ctype, _, _, interlace = ihdr
    if depth != 8 or ctype not in (2, 6) or interlace:
        fail(f"{name}: bit depth {depth}, colour type {ctype}, interlace {interlace}; expected 8-bit RGB(A)")
    ch = 4 if ctype == 6 else 3
    raw = zlib.decompress(b"".join(idat))
    stride = w * ch
    if len(raw) != h * (stride + 1):
        fail(f"{name}: {len(raw)} bytes of image data; expected {h * (stride + 1)}")
    out = np.zeros((h, stride), dtype=np.uint8)
    prev = np.zeros(stride, dtype=np.int32)
    for y in range(h):
        f = raw[y * (stride + 1)]
        line = np.frombuffer(raw, dtype=np.uint8, count=stride, offset=y * (stride + 1) + 1).astype(np.int32)
        if f == 0:
            cur = line
        elif f == 2:
            cur = (line + prev) & 255
        elif f in (1, 3, 4):  # these depend on the decoded bytes to the left: byte by byte
            cur = np.zeros(stride, dtype=np.int32)
            for x in range(stride):
                a = cur[x - ch] if x >= ch else 0
                b = prev[x]
                c = prev[x - ch] if x >= ch else 0
                pred = a if f == 1 else (a + b) // 2 if f == 3 else paeth(a, b, c)
                cur[x] = (line[x] + pred) & 255
        else:
            fail(f"{name}: row {y} has filter type {f}; expected 0..4")
        out[y] = cur
        prev = cur
    px = out.reshape(h, w, ch)
    if ch == 3:
        px = np.concatenate([px, np.full((h, w, 1), 255, dtype=np.uint8)], axis=2)
    return px


def row_filters(data):
    """The filter type of each row of a PNG (8-bit RGB(A)): which decoding paths a file takes."""
    pos, idat, ihdr = 8, [], None
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        if kind == b"IHDR":
            ihdr = struct.unpack(">IIBBBBB", data[pos + 8:pos + 8 + length])
        elif kind == b"IDAT":
            idat.append(data[pos + 8:pos + 8 + length])
        pos += 12 + length
    w, h, ctype = ihdr[0], ihdr[1], ihdr[3]
    raw = zlib.decompress(b"".join(idat))
    stride = w * (4 if ctype == 6 else 3) + 1
    return [raw[y * stride] for y in range(h)]


def read_stack(path):
    if os.path.isdir(path):
        files = {n: os.path.join(path, n) for n in os.listdir(path)}
        load = lambda n: open(files[n], "rb").read()
    else:
        z = zipfile.ZipFile(path)
        files = {i.filename.split("/")[-1]: i.filename for i in z.infolist() if not i.is_dir()}
        load = lambda n: z.read(files[n])
    if "ConfigFile.xml" not in files:
        fail(f"{path}: ConfigFile.xml not found")
    cfg = parse_config(load("ConfigFile.xml"))
    prefix, start, n = cfg["ImageFilePrefix"], cfg["StartIndex"], cfg["NumberOfSlices"]

    def leading_int(s):
        m = re.match(r"\s*[+-]?[0-9]+", s)
        return int(m.group()) if m else None

    keys = {tuple(m["rgba"]): m["name"] for m in cfg["MaterialList"]}
    bg = tuple(cfg["Background"]) if cfg["Background"] else None
    counts = {m["name"]: 0 for m in cfg["MaterialList"]}
    void, census = 0, {}
    for i in range(start, start + n):
        name = f"{prefix}{i}.png"
        if name not in files:
            name = next((k for k in files if k.endswith(".png") and leading_int(k.replace(prefix, "", 1).replace(".png", "")) == i), None)
        if name is None:
            fail(f"Missing slice image for index {i}")
        px = decode_png(load(name), name)
        if px.shape[:2] != (cfg["SliceHeight"], cfg["SliceWidth"]):
            fail(f"{name}: {px.shape[1]} x {px.shape[0]} px; expected {cfg['SliceWidth']} x {cfg['SliceHeight']}")
        flat = px.reshape(-1, 4)
        colours, cnt = np.unique(flat, axis=0, return_counts=True)
        for c, k in zip(map(tuple, colours.tolist()), cnt.tolist()):
            census[" ".join(map(str, c))] = census.get(" ".join(map(str, c)), 0) + k
            if c == bg or c[3] == 0:
                void += k
            elif c in keys:
                counts[keys[c]] += k
            else:
                fail(f"{name}: {k} pixels of colour {c}, neither a material nor the background")
    return {"config": cfg, "counts": counts, "void": void, "pixels": census}


if __name__ == "__main__":
    print(json.dumps(read_stack(sys.argv[1])))
