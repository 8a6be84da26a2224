#!/usr/bin/env bash
# Installs the dependencies, builds trivox (optimised, assertions on) and runs every test.
# Usage: tools/test.sh            (build folder: build/; BUILD_DIR overrides)
# The sanitized build and the fuzzers run by hand (tools/sanitize.sh, tools/fuzz.sh): they do not
# yet fit CI's time (docs/testing.md, "In CI: the time budget").
# tools/demo.sh builds in its own folder (build-demo/, assertions off), so neither script's
# TRIVOX_ASSERTIONS stays in the other's CMake cache.
set -euo pipefail
cd "$(dirname "$0")/.."
tools/setup.sh
build=${BUILD_DIR:-build}
jobs=$(nproc 2>/dev/null || echo 2)
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DTRIVOX_ASSERTIONS=ON >/dev/null
cmake --build "$build" -j "$jobs"
ctest --test-dir "$build" --output-on-failure -j "$jobs"
