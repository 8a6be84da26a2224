#!/usr/bin/env python3
"""Writes models/fillet_spheres.json: the two tri-cubic spheres of Masalha, Cirillo & Elber 2021
(Fig. 13), each with its own rgb field, and the fillet operation between them.

Each sphere is one tricubic Bezier cell: the 4 x 4 x 4 control points of the cube [-1, 1]^3 at
uniform parameters, pushed radially onto spheres (g |g|_inf / |g|_2), scaled by the radius. Its
six faces are bulging bicubic patches; the spheres overlap so that their facing faces (u1 of
"left", u0 of "right") meet in one closed curve inside both faces. Colours are cubic in the
cell's parameters (so exact in the cell): "left" runs from red at the bottom to yellow at the
top, "right" from blue at the back to green at the front.
"""
import json
import math
import sys

R, GAP, N = 10.0, 15.0, 4  # radius, distance of the centres, control points per direction


def ball(centre, colour):
    pts = []
    for k in range(N):
        for j in range(N):
            for i in range(N):
                g = [-1.0 + 2.0 * t / (N - 1) for t in (i, j, k)]
                inf = max(abs(c) for c in g)
                two = math.sqrt(sum(c * c for c in g))
                xyz = [centre[a] + R * g[a] * inf / two for a in range(3)]
                uvw = (i / (N - 1), j / (N - 1), k / (N - 1))
                pts.append([round(c, 9) for c in xyz] + [round(c, 9) for c in colour(*uvw)])
    bez = [0.0] * N + [1.0] * N
    return {"orders": [N, N, N], "knots": [bez, bez, bez], "points": pts}


model = {
    "trivox": 1,
    "units": "mm",
    "properties": ["r", "g", "b"],
    "cells": [
        {"name": "left", "trivariate": ball([0.0, 0.0, 0.0], lambda u, v, w: [1.0, w, 0.1])},
        {"name": "right", "trivariate": ball([GAP, 0.0, 0.0], lambda u, v, w: [0.1, v, 1.0 - v])},
    ],
    "operations": [
        {"op": "fillet", "name": "fillet", "between": [{"cell": "left", "face": "u1"}, {"cell": "right", "face": "u0"}],
         "distance": [1.0, 1.0], "tau": 1.0, "section": "hermite", "method": "auto", "blend": "parametric"}
    ],
}
out = sys.argv[1] if len(sys.argv) > 1 else "models/fillet_spheres.json"
with open(out, "w") as f:
    json.dump(model, f, indent=1)
    f.write("\n")
