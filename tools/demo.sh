#!/usr/bin/env bash
# The main job on the default model: installs, builds, then runs trivox on models/ and writes
# what it produced to output/.
set -euo pipefail
cd "$(dirname "$0")/.."
tools/setup.sh
build=${BUILD_DIR:-build}
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
cmake --build "$build" -j "$(nproc 2>/dev/null || echo 2)" --target trivox
mkdir -p output
model=models/graded_block.json
"$build/trivox" info "$model" | tee output/info.txt
"$build/trivox" info "$model" --json > output/info.json
"$build/trivox" eval "$model" --cell block --uvw 0.5,0.5,0.5 | tee -a output/info.txt
echo "demo: wrote output/info.txt and output/info.json"
