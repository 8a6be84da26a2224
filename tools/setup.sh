#!/usr/bin/env bash
# Installs every build and test dependency of trivox from Debian 12 packages.
# Idempotent and quiet: does nothing when all packages are present; uses sudo only when not root.
set -euo pipefail

# Build: the compiler and tools; Eigen, TBB, nlohmann/json, CLI11, pugixml (G+Smo XML and
# ConfigFile.xml), libzip (.gcvf), OpenSSL (SHA-256), OpenVDB (with Boost iostreams), lib3mf
# (3MF meshes), OpenImageIO (the PNG module; its CMake package wants OpenCV's headers and its
# own tools).
# Tests: Catch2, OpenVDB's tools (vdb_print, vdb_render) and the Python modules of OpenVDB and
# OpenImageIO as independent readers, unzip for the .gcvf archives, Blender (run headless) as a
# real client of the VDB volumes and the meshes, admesh as an independent checker of STL meshes,
# Slurm and munge (a one-node cluster started by a test) and PyYAML (the Kubernetes Job
# manifests of docs/jobs.md) for the schedulers users run trivox on.
# Sanitizers and fuzzing (tools/sanitize.sh, tools/fuzz.sh): clang 14 and its runtimes (ASan,
# UBSan, libFuzzer for -fsanitize=fuzzer), which clang only recommends.
packages=(
  build-essential cmake ninja-build pkg-config
  libeigen3-dev libtbb-dev nlohmann-json3-dev libcli11-dev libpugixml-dev libzip-dev libssl-dev
  libopenvdb-dev libboost-iostreams-dev
  libopenimageio-dev libopencv-core-dev openimageio-tools
  catch2 libopenvdb-tools python3-openvdb python3-openimageio unzip blender
  lib3mf-dev admesh
  slurm-wlm munge python3-yaml
  clang libclang-rt-14-dev
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
[ ${#missing[@]} -eq 0 ] && exit 0

SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
echo "setup: installing ${#missing[@]} packages: ${missing[*]}" >&2
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq >/dev/null
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
