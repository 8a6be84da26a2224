#!/usr/bin/env bash
# Regenerates the pictures of README.md in docs/images/ from the demo's outputs: the rendered
# teapot (output/teapot.png, `trivox render` of its OpenVDB volume) and the contact sheet of its
# Voxel Print stack (output/teapot-preview.png, `trivox preview`). Runs tools/demo.sh first when
# either is missing, then downsizes both with oiiotool (openimageio-tools, which tools/setup.sh
# installs) to at most WIDTH pixels across (default 560), drops an alpha channel that is opaque
# everywhere and compresses at zlib's level 9, so each stays well under 300 KB.
# Usage: tools/make_images.sh [WIDTH]
set -euo pipefail
cd "$(dirname "$0")/.."
width=${1:-560}
if [ ! -f output/teapot.png ] || [ ! -f output/teapot-preview.png ]; then
  tools/demo.sh
fi
command -v oiiotool >/dev/null || tools/setup.sh
mkdir -p docs/images
# name in docs/images  <-  demo output
for pair in "teapot-render.png output/teapot.png" "teapot-contact-sheet.png output/teapot-preview.png"; do
  set -- $pair
  out=docs/images/$1 src=$2
  w=$(oiiotool --info -v "$src" | sed -n 's/.* \([0-9]*\) x  *[0-9]*,.*/\1/p' | head -n 1)
  resize=()
  if [ -n "$w" ] && [ "$w" -gt "$width" ]; then resize=(--resize "${width}x0"); fi
  # The minimum of each channel; a fourth (alpha) that never drops below 255 carries nothing.
  alpha_min=$(oiiotool --stats "$src" | sed -n 's/.*Stats Min: *//p' | head -n 1 | awk '{print $4}')
  channels=()
  if [ "$alpha_min" = 255 ]; then channels=(--ch R,G,B); fi
  oiiotool --nosoftwareattrib "$src" "${resize[@]}" "${channels[@]}" --attrib png:compressionLevel 9 -o "$out"
  echo "make_images: $out ($(oiiotool --info "$out" | sed -n 's/.*: *\([0-9]* x *[0-9]*\).*/\1/p' | head -n 1), $(stat -c %s "$out") bytes)"
done
