#!/usr/bin/env python3
"""Writes models/twisted_column.json: the demo model of the print job.

A column 24 x 24 x 20 mm, twisted by a quarter turn and bulging at mid-height, made of four
tricubic Bezier cells stacked in z (they share their faces exactly, so they glue), with an rgb
colour field that runs through the hues with height and fades to white towards the axis.
Control points sit on the map F at the Bezier cells' uniform parameters; properties likewise.
"""
import json
import math
import sys

SIZE, HEIGHT, CELLS, N = 24.0, 20.0, 4, 4  # N control points per direction (tricubic)


def shape(u, v, z):
    """xyz of the column at square coordinates (u, v) in [0,1]^2 and height z."""
    t = z / HEIGHT
    twist = 0.5 * math.pi * t
    bulge = 1.0 + 0.25 * math.sin(math.pi * t)
    x, y = (u - 0.5) * SIZE * bulge, (v - 0.5) * SIZE * bulge
    c, s = math.cos(twist), math.sin(twist)
    return [SIZE / 2 * 1.3 + c * x - s * y, SIZE / 2 * 1.3 + s * x + c * y, z]


def colour(u, v, z):
    h = z / HEIGHT
    r = [0.5 + 0.5 * math.cos(2 * math.pi * (h - k / 3.0)) for k in range(3)]
    radial = min(1.0, 2.0 * max(abs(u - 0.5), abs(v - 0.5)))  # 0 on the axis, 1 on the skin
    return [round(1.0 - radial * (1.0 - c), 6) for c in r]


def cell(k):
    pts = []
    for kk in range(N):
        z = HEIGHT * (k + kk / (N - 1)) / CELLS
        for j in range(N):
            for i in range(N):
                u, v = i / (N - 1), j / (N - 1)
                pts.append([round(c, 6) for c in shape(u, v, z)] + colour(u, v, z))
    bez = [0.0] * N + [1.0] * N
    return {"name": f"ring{k}", "trivariate": {"orders": [N, N, N], "knots": [bez, bez, bez], "points": pts}}


model = {"trivox": 1, "units": "mm", "properties": ["r", "g", "b"],
         "cells": [cell(k) for k in range(CELLS)], "operations": []}
out = sys.argv[1] if len(sys.argv) > 1 else "models/twisted_column.json"
with open(out, "w") as f:
    json.dump(model, f, indent=1)
