#!/usr/bin/env bash
# The main job on the default model: installs what is missing, builds, then slices
# models/twisted_column.json (four tricubic cells with an rgb field) at GrabCAD J750 settings into
# output/twisted_column/ (a Voxel Print PNG stack + ConfigFile.xml), prints the summary, and
# writes a contact sheet of the stack to output/twisted_column-preview.png.
set -euo pipefail
cd "$(dirname "$0")/.."
tools/setup.sh
build=${BUILD_DIR:-build}
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
cmake --build "$build" -j "$(nproc 2>/dev/null || echo 2)" --target trivox
model=models/twisted_column.json
mkdir -p output
"$build/trivox" info "$model"
echo
"$build/trivox" slice "$model" -o output/twisted_column --printer j750 --force
"$build/trivox" inspect output/twisted_column
"$build/trivox" preview output/twisted_column -o output/twisted_column-preview.png
echo "demo: slices in output/twisted_column/, contact sheet output/twisted_column-preview.png"
