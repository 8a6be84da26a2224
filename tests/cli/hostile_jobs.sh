#!/usr/bin/env bash
# A job folder trivox can be trusted with (docs/jobs.md, "Confinement"): names read from
# manifests never lead out of the folder, --force removes only what trivox provably wrote,
# --resume does not keep a slice that is a link to a file elsewhere and clears a killed run's
# temporary files. Truths: files outside the folder keep their bytes (cmp against copies), the
# user's files stay, and the repaired folders are byte for byte what one clean job writes.
set -euo pipefail
source tests/cli/lib.bash "$@"

model=models/graded_block.json
grid=(--dpi 100,100 --layer 1 --progress never)    # 158 x 79 pixels, 44 layers
sha() { sha256sum "$1" | cut -d' ' -f1; }
same_folder() {  # every file of $1 is in $2 with the same bytes (and $2 may hold more: $3 names them)
  local extra=${3:-}
  [ "$( (cd "$1" && ls; [ -z "$extra" ] || printf '%s\n' $extra) | sort)" = "$(cd "$2" && ls | sort)" ] \
    || { echo "different files: $1 $2"; diff <(ls "$1") <(ls "$2"); exit 1; }
  for f in "$1"/*; do cmp "$f" "$2/$(basename "$f")"; done
}
# edit_manifest FILE PYTHON: runs PYTHON with the parsed manifest as m, then writes it back.
edit_manifest() {
  "$py" - "$1" "$2" <<'PY'
import sys, json
p, code = sys.argv[1], sys.argv[2]
m = json.load(open(p))
exec(code)
json.dump(m, open(p, "w"), indent=2)
PY
}

"$trivox" slice $model -o "$tmp/clean/job" "${grid[@]}" > /dev/null

# 1. merge follows no path a shard manifest lists: a VDB part named ../outside/victim.vdb (a
#    copy of a real part, so that its SHA-256 matches), an absolute path, or a plain name
#    other than the part's own are refused (exit 2), and the victim keeps its bytes.
vdb=(--progress never --vdb --vdb-voxel 0.5)
for k in 0 1; do "$trivox" slice $model -o "$tmp/m/job" "${vdb[@]}" --shard $k/2 > /dev/null; done
mkdir "$tmp/m/outside"
cp "$tmp/m/job/graded_block.shard-1-of-2.vdb" "$tmp/m/outside/victim.vdb"
cp "$tmp/m/outside/victim.vdb" "$tmp/victim.copy"
cp "$tmp/m/job/manifest.shard-1-of-2.json" "$tmp/part1.json"
edit_manifest "$tmp/m/job/manifest.shard-1-of-2.json" 'm["files"][0]["file"] = "../outside/victim.vdb"'
expect_fail 'manifest.shard-1-of-2.json: /files/0/file: found the string "../outside/victim.vdb"; expected a file name inside the folder' \
  "$trivox" merge "$tmp/m/job"
cmp "$tmp/victim.copy" "$tmp/m/outside/victim.vdb"
[ ! -e "$tmp/m/job/manifest.json" ]
echo secret > "$tmp/secret"
edit_manifest "$tmp/m/job/manifest.shard-1-of-2.json" "m['files'][0]['file'] = '$tmp/secret'; m['files'][0]['sha256'] = '$(sha "$tmp/secret")'"
expect_fail "/files/0/file: found the string .*; expected a file name inside the folder" "$trivox" merge "$tmp/m/job"
cp "$tmp/m/job/graded_block.shard-1-of-2.vdb" "$tmp/m/job/victim.shard-1-of-2.vdb"
edit_manifest "$tmp/m/job/manifest.shard-1-of-2.json" 'm["files"][0]["file"] = "victim.shard-1-of-2.vdb"'
expect_fail 'shard 1/2: lists its vdb file as "victim.shard-1-of-2.vdb"; expected "graded_block.shard-1-of-2.vdb"' \
  "$trivox" merge "$tmp/m/job"
[ ! -e "$tmp/m/job/victim.vdb" ]
[ ! -e "$tmp/m/job/manifest.json" ]
# A part that is a link to a file elsewhere, even of the right bytes, is not the shard's file.
cp "$tmp/part1.json" "$tmp/m/job/manifest.shard-1-of-2.json"
mv "$tmp/m/job/graded_block.shard-1-of-2.vdb" "$tmp/m/outside/part1.vdb"
ln -s "$tmp/m/outside/part1.vdb" "$tmp/m/job/graded_block.shard-1-of-2.vdb"
expect_fail "shard 1/2: 1 file(s) missing or changed" "$trivox" merge "$tmp/m/job"
rm "$tmp/m/job/graded_block.shard-1-of-2.vdb"
mv "$tmp/m/outside/part1.vdb" "$tmp/m/job/graded_block.shard-1-of-2.vdb"
"$trivox" merge "$tmp/m/job" > /dev/null
"$trivox" slice $model -o "$tmp/m/whole" "${vdb[@]}" > /dev/null
cmp "$tmp/m/whole/graded_block.vdb" "$tmp/m/job/graded_block.vdb"
# The archive's entry must be the folder's own ../<folder>.gcvf.
for k in 0 1; do "$trivox" slice $model -o "$tmp/z/job" "${grid[@]}" --zip --shard $k/2 > /dev/null; done
edit_manifest "$tmp/z/job/manifest.shard-0-of-2.json" "m['files'].append({'role': 'zip', 'file': '../other.gcvf', 'sha256': '$(sha "$tmp/secret")'})"
expect_fail 'lists its zip file as "../other.gcvf"; expected "../job.gcvf"' "$trivox" merge "$tmp/z/job"

# 2. --force removes no file a manifest names unless it is what trivox wrote there: a manifest
#    listing the user's notes.txt as a VDB is not trivox's (moved aside, said on stderr), and the
#    notes stay; the folder is then the clean job's plus the notes and the moved manifest.
cp -r "$tmp/clean/job" "$tmp/f1"
echo "my notes" > "$tmp/f1/notes.txt"
edit_manifest "$tmp/f1/manifest.json" "m['files'].append({'role': 'vdb', 'file': 'notes.txt', 'sha256': '$(sha "$tmp/f1/notes.txt")'})"
"$trivox" slice $model -o "$tmp/f1" "${grid[@]}" --force > /dev/null 2> "$tmp/err"
grep -q "manifest.json: not a manifest this trivox can read .*; moved aside to manifest.json.damaged-1" "$tmp/err" || { cat "$tmp/err"; exit 1; }
[ "$(cat "$tmp/f1/notes.txt")" = "my notes" ]
same_folder "$tmp/clean/job" "$tmp/f1" "notes.txt manifest.json.damaged-1"
# A readable manifest: its VDB goes when its bytes are those recorded, stays when changed.
"$trivox" slice $model -o "$tmp/f2" "${grid[@]}" --png --vdb --vdb-voxel 0.5 > /dev/null
echo "changed" >> "$tmp/f2/graded_block.vdb"
"$trivox" slice $model -o "$tmp/f2" "${grid[@]}" --force > /dev/null 2> "$tmp/err"
grep -q "graded_block.vdb: kept: listed by manifest.json but not the file it lists" "$tmp/err" || { cat "$tmp/err"; exit 1; }
same_folder "$tmp/clean/job" "$tmp/f2" "graded_block.vdb"

# 3. A folder that never held a trivox job: --force removes nothing there (slice-named files
#    past the job's end included) and says so; the job's own names are replaced.
mkdir "$tmp/f3"
echo "not a slice" > "$tmp/f3/slice_500.png"
echo "photo" > "$tmp/f3/photo.png"
echo "old" > "$tmp/f3/slice_0.png"
"$trivox" slice $model -o "$tmp/f3" "${grid[@]}" --force > /dev/null 2> "$tmp/err"
grep -q "holds no trivox manifest, so --force removes nothing there.*1 slice file(s) past this job's last layer" "$tmp/err" || { cat "$tmp/err"; exit 1; }
[ "$(cat "$tmp/f3/slice_500.png")" = "not a slice" ]
[ "$(cat "$tmp/f3/photo.png")" = photo ]
same_folder "$tmp/clean/job" "$tmp/f3" "slice_500.png photo.png"

# 4. A damaged or foreign manifest.json: --resume says to use --force (exit 2); --force moves
#    it aside and starts over; a second one goes to the next free name.
mkdir "$tmp/f4"
echo '{"name": "my web app", "start_url": "/"}' > "$tmp/f4/manifest.json"
expect_fail "manifest.json: top level: no \"trivox_manifest\"; expected one" "$trivox" slice $model -o "$tmp/f4" "${grid[@]}" --resume
"$trivox" slice $model -o "$tmp/f4" "${grid[@]}" --force > /dev/null 2> "$tmp/err"
grep -q "moved aside to manifest.json.damaged-1" "$tmp/err" || { cat "$tmp/err"; exit 1; }
printf '{"trivox_manifest": 1, "trivox"' > "$tmp/f4/manifest.json"   # cut short
"$trivox" slice $model -o "$tmp/f4" "${grid[@]}" --force > /dev/null 2> "$tmp/err"
grep -q "moved aside to manifest.json.damaged-2" "$tmp/err" || { cat "$tmp/err"; exit 1; }
grep -q "my web app" "$tmp/f4/manifest.json.damaged-1"
same_folder "$tmp/clean/job" "$tmp/f4" "manifest.json.damaged-1 manifest.json.damaged-2"
# A manifest that is a link to a file elsewhere is not read (nor echoed), and is not followed.
mkdir "$tmp/f5"
ln -s "$tmp/secret" "$tmp/f5/manifest.json"
expect_fail "manifest.json: is a symbolic link; expected a regular file" "$trivox" slice $model -o "$tmp/f5" "${grid[@]}" --resume
if grep -q secret "$tmp/err"; then echo "the link's target was echoed"; exit 1; fi

# 5. --resume: a listed slice that is a link to a file elsewhere with the same bytes is redone
#    into a real file, the link replaced and its target untouched; temporary files of a killed
#    run (of this job's names only) are removed.
cp -r "$tmp/clean/job" "$tmp/r1"
rm "$tmp/r1/ConfigFile.xml"
cp "$tmp/r1/slice_3.png" "$tmp/outside3.png"
cp "$tmp/outside3.png" "$tmp/outside3.copy"
rm "$tmp/r1/slice_3.png" && ln -s "$tmp/outside3.png" "$tmp/r1/slice_3.png"
echo "elsewhere" > "$tmp/outside7.png"
rm "$tmp/r1/slice_7.png" && ln -s "$tmp/outside7.png" "$tmp/r1/slice_7.png"
for f in .slice_5.png.tmp-4242-9af3-0 .manifest.json.tmp-4242-1 .ConfigFile.xml.tmp-4242-77-2 .notes.txt.tmp-4242-0; do
  echo partial > "$tmp/r1/$f"
done
"$trivox" slice $model -o "$tmp/r1" "${grid[@]}" --resume --json > "$tmp/r1.json" 2> "$tmp/err"
grep -q "removed 3 temporary file(s) left by an earlier run" "$tmp/err" || { cat "$tmp/err"; exit 1; }
"$py" - "$tmp/r1.json" <<'PY'
import sys, json
s = json.load(open(sys.argv[1]))
assert s["layers_kept"] == 44 - 2, s["layers_kept"]   # all but the two links
PY
[ ! -L "$tmp/r1/slice_3.png" ]
[ -f "$tmp/r1/slice_3.png" ]
[ ! -L "$tmp/r1/slice_7.png" ]
cmp "$tmp/outside3.copy" "$tmp/outside3.png"
[ "$(cat "$tmp/outside7.png")" = elsewhere ]
[ -e "$tmp/r1/.notes.txt.tmp-4242-0" ]
rm "$tmp/r1/.notes.txt.tmp-4242-0"
same_folder "$tmp/clean/job" "$tmp/r1"
echo "hostile jobs: ok"
