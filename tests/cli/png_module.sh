#!/usr/bin/env bash
# End-to-end: the PNG code is a module, libtrivox_png.so, loaded on the first PNG encoded or
# decoded (src/io/png_codec.hpp), so the binary does not link OpenImageIO (whose Debian package
# brings about 260 libraries and cost every command 0.33 s at start).
# Truths: ldd of the binary names no OpenImageIO; TRIVOX_PLUGIN_DIR, when set, is the only folder
# searched, so naming an empty one makes the module unfindable: commands that touch no PNG still
# work, a PNG job fails with exit 1 naming the path tried (before making its folder), and
# `inspect` of a stack fails the same way. The module is found next to the binary, through the
# variable, and, for a copy of the binary elsewhere, in the build folder compiled in; all three
# write the same bytes.
set -euo pipefail
source tests/cli/lib.bash "$@"

if ldd "$trivox" | grep -i openimageio; then echo "$trivox links OpenImageIO"; exit 1; fi
bin_dir=$(dirname "$(readlink -f "$trivox")")
[ -f "$bin_dir/libtrivox_png.so" ] || { echo "no libtrivox_png.so next to $trivox"; exit 1; }

job=(--dpi 100,100 --layer 0.254 --progress never)
"$trivox" slice models/gismo/fichera.xml -o "$tmp/a" "${job[@]}" > /dev/null
TRIVOX_PLUGIN_DIR=$bin_dir "$trivox" slice models/gismo/fichera.xml -o "$tmp/b" "${job[@]}" > /dev/null
mkdir "$tmp/bin"
ln "$trivox" "$tmp/bin/trivox" 2> /dev/null || cp "$trivox" "$tmp/bin/trivox"   # a hard link: no 190 MB copy
"$tmp/bin/trivox" slice models/gismo/fichera.xml -o "$tmp/c" "${job[@]}" > /dev/null
[ "$(ls "$tmp"/a/*.png | wc -l)" -eq 8 ]
for d in b c; do for f in "$tmp"/a/*.png; do cmp "$f" "$tmp/$d/$(basename "$f")"; done; done
"$trivox" inspect "$tmp/a" > /dev/null

mkdir "$tmp/empty"
missing=(env TRIVOX_PLUGIN_DIR="$tmp/empty")
"${missing[@]}" "$trivox" --version > /dev/null
"${missing[@]}" "$trivox" info models/graded_block.json > /dev/null
"${missing[@]}" "$trivox" eval models/graded_block.json --cell block --uvw 0.5,0.5,0.5 > /dev/null
tried="cannot load the PNG module libtrivox_png.so: tried $tmp/empty/libtrivox_png.so ("
expect_failed "$tried" "$tmp/none" "${missing[@]}" "$trivox" slice models/gismo/fichera.xml -o "$tmp/none" "${job[@]}"
grep -q "No such file or directory" "$tmp/err" || { echo "no dlerror text:"; cat "$tmp/err"; exit 1; }
expect_failed "$tried" - "${missing[@]}" "$trivox" inspect "$tmp/a"
echo "cli png module: ok"
