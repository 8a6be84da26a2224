#!/usr/bin/env bash
# The V-rep paper's solids (Massarwi & Elber 2016, Sec. 6, Figs. 15-17, Table 1) rebuilt as the
# scenes models/vrep_solid_{a,b,c}.json: per solid, the time of `trivox build` (primitives, the
# Booleans, the untrimming of box pieces, writing the model, and the build report, whose volumes
# of trimmed pieces come from their boundary faces) and of `trivox info` on the built model (every
# piece measured on its boundary faces, and the topology): medians and ranges of the wall time
# over REPEATS runs, and median CPU times (user + system, steadier on a shared machine), beside
# Table 1's Boolean times (total, of which gluing) on the paper's i7 2.7 GHz. `trivox build`
# measures every piece as `trivox info` does, so build - info estimates the Booleans and the
# untrimming alone.
# Not a test: speed is never tested (docs/performance.md).
#
#   tools/bench/vrep_solids.sh [TRIVOX [REPEATS]]     (defaults: build/trivox, 3)
set -euo pipefail
here=$(cd "$(dirname "$0")/../.." && pwd)
trivox=${1:-$here/build/trivox}
repeats=${2:-3}
[ -x "$trivox" ] || { echo "vrep_solids.sh: $trivox is not an executable; expected the trivox binary (build it first)" >&2; exit 2; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# seconds COMMAND...: run it, print its wall time and CPU time (user + system) in seconds.
seconds() {
  /usr/bin/time -f "%e %U %S" -o "$tmp/time" "$@" > "$tmp/out" 2> "$tmp/err" ||
    { echo "vrep_solids.sh: failed: $*" >&2; cat "$tmp/err" >&2; exit 1; }
  read -r wall user sys < "$tmp/time"
  echo "$wall:$(echo "$user + $sys" | bc -l)"
}

echo "trivox: $trivox ($("$trivox" --version 2>/dev/null | head -1)); $(nproc) cores; $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ *//'); $repeats runs each"
printf '%-13s %-7s %-11s %-17s %-21s %-21s %-13s %s\n' solid figure "cells (paper)" "paper s (gluing)" "build s (range)" "info s (range)" "build - info" "paper / build"
for s in a:15:7:2.9:0.08 b:16:12:17.6:0.98 c:17:19:6.2:0.24; do
  IFS=: read -r name fig paper_cells paper_total paper_glue <<< "$s"
  scene=$here/models/vrep_solid_$name.json
  builds=() infos=()
  for ((i = 0; i < repeats; ++i)); do
    builds+=("$(seconds "$trivox" build "$scene" -o "$tmp/m.json" --force --json)")
    cells=$(python3 -c 'import json,sys; print(len(json.load(open(sys.argv[1]))["cells"]))' "$tmp/out")
    infos+=("$(seconds "$trivox" info "$tmp/m.json" --json)")
  done
  python3 - "$name" "$fig" "$cells" "$paper_cells" "$paper_total" "$paper_glue" "${builds[*]}" "${infos[*]}" <<'PY'
import sys, statistics
name, fig, cells, pc, pt, pg = sys.argv[1:7]
def runs(arg):  # wall and CPU medians and ranges
    w = sorted(float(x.split(":")[0]) for x in arg.split()); c = sorted(float(x.split(":")[1]) for x in arg.split())
    return statistics.median(w), w, statistics.median(c)
bw, bws, bc = runs(sys.argv[7]); iw, iws, ic = runs(sys.argv[8])
print(f"{'vrep_solid_' + name:<13} Fig. {fig:<2} {cells + ' (' + pc + ')':<13} {pt + ' (' + pg + ')':<17} "
      f"{f'{bw:.2f} ({bws[0]:.2f}-{bws[-1]:.2f})':<21} {f'{iw:.2f} ({iws[0]:.2f}-{iws[-1]:.2f})':<21} {bw - iw:<13.2f} {float(pt) / bw:.2f}")
print(f"{'':<13} {'CPU':<7} {'':<13} {'':<17} {bc:<21.2f} {ic:<21.2f} {bc - ic:<13.2f} {float(pt) / bc:.2f}")
PY
done
