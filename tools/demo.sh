#!/usr/bin/env bash
# The main job on the default model, the heterogeneous Utah teapot (Masalha et al. 2021, Sec. 8):
# installs what is missing, builds, turns the scene models/teapot.json (Newell's patches from
# models/gismo/teapot.xml, 10 x: 63 x 40 x 31 mm; shells, tube solids, an rgb field per part,
# fitted fillets body-spout and body-handle) into
# a model (printing each cell's validity), slices it at GrabCAD J750 settings into output/teapot/ (a Voxel Print PNG
# stack + ConfigFile.xml and the OpenVDB volume output/teapot/teapot.vdb), prints the summary, and
# writes a contact sheet (output/teapot-preview.png) and a rendered picture (output/teapot.png).
# About a minute and a quarter on 2 cores (the PNG slice: 1159 layers of 1489 x 473 pixels, about
# 15 s; the VDB about 19 s).
set -euo pipefail
cd "$(dirname "$0")/.."
tools/setup.sh
# Its own build folder, assertions off (the tests' build/ keeps them on); BUILD_DIR overrides.
build=${BUILD_DIR:-build-demo}
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DTRIVOX_ASSERTIONS=OFF >/dev/null
cmake --build "$build" -j "$(nproc 2>/dev/null || echo 2)" --target trivox
trivox=$build/trivox
mkdir -p output
# build prints every cell's validity: the exact det J check for the parts, and for the fillet
# cells, whose det J vanishes along their rails by construction (Masalha et al. 2021, Sec. 9), the
# sign of det J sampled inside (docs/fillets.md, "Quality report").
"$trivox" build models/teapot.json -o output/teapot.json --force
echo
"$trivox" info output/teapot.json
echo
"$trivox" slice output/teapot.json -o output/teapot --printer j750 --png --vdb --force
"$trivox" inspect output/teapot
"$trivox" inspect output/teapot/teapot.vdb
"$trivox" preview output/teapot -o output/teapot-preview.png
"$trivox" render output/teapot/teapot.vdb -o output/teapot.png --force
echo "demo: slices and teapot.vdb in output/teapot/, contact sheet output/teapot-preview.png, picture output/teapot.png"
