#!/usr/bin/env bash
# End-to-end: hostile inputs of the readers (docs/testing.md, "Fuzzing"). Every file of
# tests/data/fuzz/ is an input a fuzz target found or that a reader once mishandled, named
# <target>-<what>.<ext> after the target of fuzz/seeds.txt whose reader it reaches. The ordinary
# trivox loads each through the command that reads such files and must refuse it: exit 2, nothing
# on stdout, and a message on stderr that names the file read and what was expected. Inputs too
# big to keep in the repository (a 1 MB cell name) are written here from a small recipe.
set -euo pipefail
source tests/cli/lib.bash "$@"

# refused FILE command...: exit 2, no stdout, stderr naming FILE with "; expected".
refused() {
  local file=$1; shift
  set +e
  "$@" > "$tmp/out" 2> "$tmp/err"
  local rc=$?
  set -e
  if [ $rc -ne 2 ]; then echo "$file: expected exit 2, got $rc: $*"; cat "$tmp/err"; exit 1; fi
  if [ -s "$tmp/out" ]; then echo "$file: unexpected stdout: $*"; head -c 2000 "$tmp/out"; exit 1; fi
  if ! grep -qF -- "trivox: error: $file" "$tmp/err"; then
    echo "$file: the message does not name the file: $*"; head -c 2000 "$tmp/err"; exit 1
  fi
  if ! grep -q -- "; expected" "$tmp/err"; then echo "$file: the message says nothing expected: $*"; head -c 2000 "$tmp/err"; exit 1; fi
  if [ "$(wc -c < "$tmp/err")" -gt 4096 ]; then echo "$file: a message of $(wc -c < "$tmp/err") bytes: $*"; exit 1; fi
}

# load TARGET FILE: FILE through the command of trivox that reads what TARGET's reader reads.
load() {
  local target=$1 file=$2 dir
  case $target in
    model_json|gismo_xml)
      refused "$file" "$trivox" info "$file" ;;
    scene)
      refused "$file" "$trivox" build "$file" -o "$tmp/built.json"
      [ ! -e "$tmp/built.json" ] || { echo "$file: a model was written"; exit 1; } ;;
    construct)
      refused "$file" "$trivox" construct "$file" -o "$tmp/constructed.json"
      [ ! -e "$tmp/constructed.json" ] || { echo "$file: an output was written"; exit 1; } ;;
    palette)
      refused "$file" "$trivox" slice models/graded_block.json -o "$tmp/palette_job" --palette "$file" --dry-run ;;
    manifest)
      # A job folder whose manifest is the input, resumed.
      dir=$tmp/job_$n
      mkdir "$dir"
      cp "$file" "$dir/manifest.json"
      refused "$dir/manifest.json" "$trivox" slice models/graded_block.json -o "$dir" --resume
      [ "$(ls "$dir")" = manifest.json ] || { echo "$file: the job folder changed: $(ls "$dir")"; exit 1; } ;;
    config_xml)
      # A slice folder whose ConfigFile.xml is the input, inspected.
      dir=$tmp/stack_$n
      mkdir "$dir"
      cp "$file" "$dir/ConfigFile.xml"
      refused "$dir/ConfigFile.xml" "$trivox" inspect "$dir" ;;
    *)
      echo "$file: unknown target '$target'; expected a file name <target>-<what> with a target of fuzz/seeds.txt"
      exit 1 ;;
  esac
}

n=0
declare -A seen
for file in tests/data/fuzz/*; do
  target=$(basename "$file")
  target=${target%%-*}
  grep -q "^$target " fuzz/seeds.txt || { echo "$file: '$target' is not a target of fuzz/seeds.txt"; exit 1; }
  load "$target" "$file"
  seen[$target]=1
  n=$((n + 1))
done
# The inputs the readers' history names as hostile are all here.
for target in model_json gismo_xml manifest; do
  [ -n "${seen[$target]:-}" ] || { echo "tests/data/fuzz/ has no $target input"; exit 1; }
done

# A cell name of 1 MB (the limit is 256 bytes): refused by the streaming pass without building the
# tree, for a model and for a scene.
{ printf '{"trivox": 1, "cells": [{"name": "'; head -c $((1 << 20)) /dev/zero | tr '\0' n
  printf '", "trivariate": {"orders": [2, 2, 2], "knots": [[0, 0, 1, 1], [0, 0, 1, 1], [0, 0, 1, 1]], '
  printf '"points": [[0,0,0],[1,0,0],[0,1,0],[1,1,0],[0,0,1],[1,0,1],[0,1,1],[1,1,1]]}}]}\n'; } > "$tmp/long_name.json"
refused "$tmp/long_name.json" "$trivox" info "$tmp/long_name.json"
grep -q "a name of 1048576 bytes; expected at most 256 bytes" "$tmp/err"
refused "$tmp/long_name.json" "$trivox" build "$tmp/long_name.json" -o "$tmp/built.json"
n=$((n + 2))

echo "fuzz regressions: $n inputs refused"
