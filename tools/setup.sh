#!/usr/bin/env bash
# Installs every build and test dependency of trivox from Debian 12 packages.
# Idempotent and quiet: does nothing when all packages are present; uses sudo only when not root.
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config
  libeigen3-dev libtbb-dev
  libopenvdb-dev libboost-iostreams-dev libopenvdb-tools python3-openvdb
  libopenimageio-dev libopencv-core-dev openimageio-tools python3-openimageio
  catch2 libcli11-dev nlohmann-json3-dev libspdlog-dev libfmt-dev
  libpugixml-dev libzip-dev zip unzip libssl-dev
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
