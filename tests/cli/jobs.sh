#!/usr/bin/env bash
# End-to-end: manifests, --resume, shards and `trivox merge` (docs/jobs.md).
# Truths: a resumed job, a killed-then-resumed job and the merge of shards write exactly the bytes
# of one uninterrupted job (cmp, every file); the manifest's SHA-256s are those of the files
# (Python's hashlib); broken or missing shards are named, with what to rerun.
set -euo pipefail
source tests/cli/lib.bash "$@"
trap 'kill %1 2>/dev/null || true; rm -rf "$tmp"' EXIT

model=models/graded_block.json
grid=(--dpi 100,100 --layer 0.5 --progress never)    # 158 x 79 pixels, 88 layers

same_folder() {  # every file of $1 is in $2 with the same bytes, and nothing else is
  [ "$(cd "$1" && ls | sort)" = "$(cd "$2" && ls | sort)" ] || { echo "different files: $1 $2"; diff <(ls "$1") <(ls "$2"); exit 1; }
  for f in "$1"/*; do cmp "$f" "$2/$(basename "$f")"; done
}

# 1. One whole job; its manifest agrees with the files.
"$trivox" slice $model -o "$tmp/whole" "${grid[@]}" --zip > /dev/null
"$py" - "$tmp/whole" <<'PY'
import sys, os, json, hashlib
d = sys.argv[1]
m = json.load(open(os.path.join(d, "manifest.json")))
sha = lambda p: hashlib.sha256(open(p, "rb").read()).hexdigest()
assert m["complete"] is True and m["shard"] == {"index": 0, "count": 1}
assert m["model"]["sha256"] == sha("models/graded_block.json")
nz = m["grid"][2]
assert m["layer_range"] == [0, nz] and [l["index"] for l in m["layers"]] == list(range(nz))
for l in m["layers"]:
    assert l["sha256"] == sha(os.path.join(d, l["file"])), l["file"]
files = {f["role"]: f for f in m["files"]}
assert files["config"]["sha256"] == sha(os.path.join(d, "ConfigFile.xml"))
assert files["zip"]["sha256"] == sha(os.path.join(d, files["zip"]["file"]))
# The layers' voxel counts add up to ConfigFile.xml's.
import xml.etree.ElementTree as ET
counts = {e.find("Name").text.strip(): int(e.find("VoxelCount").text) for e in ET.parse(os.path.join(d, "ConfigFile.xml")).getroot().iter("Material")}
# ConfigFile.xml lists the materials used, as the public writers do; not those never chosen.
for i, mat in enumerate(m["materials"]):
    total = sum(l["voxels"][i] for l in m["layers"])
    assert (total == counts[mat["name"]]) if total else (mat["name"] not in counts), mat
assert len(counts) < len(m["materials"]), counts   # the block uses no UltraClear
PY

# 2. An interrupted job, simulated: half the layers unlisted, one listed layer changed, one
#    deleted, ConfigFile.xml gone. --resume redoes exactly what is needed: same bytes.
# (Copies keep the folder's name, which the manifest's .gcvf entry holds: ../whole.gcvf.)
mkdir "$tmp/r" "$tmp/s"
cp -r "$tmp/whole" "$tmp/r/whole"
resumed=$tmp/r/whole sharded=$tmp/s/whole
rm "$resumed/ConfigFile.xml"
"$py" - "$resumed" <<'PY'
import sys, os, json
d = sys.argv[1]
p = os.path.join(d, "manifest.json")
m = json.load(open(p))
m["layers"] = m["layers"][: len(m["layers"]) // 2]
m["complete"] = False
m["files"] = []
json.dump(m, open(p, "w"))
open(os.path.join(d, m["layers"][3]["file"]), "ab").write(b"x")   # changed since
os.remove(os.path.join(d, m["layers"][5]["file"]))                # lost
os.remove(os.path.join(d, m["layers"][-1]["file"]))               # lost too
PY
"$trivox" slice $model -o "$resumed" "${grid[@]}" --zip --resume --json > "$tmp/resumed.json"
same_folder "$tmp/whole" "$resumed"
cmp "$tmp/whole.gcvf" "$tmp/r/whole.gcvf"
"$py" - "$tmp/resumed.json" <<'PY'
import sys, json
s = json.load(open(sys.argv[1]))
assert s["layers_kept"] == 44 - 3, s["layers_kept"]   # half of 88, less the changed and the lost
PY

# 3. A real kill: a long job killed mid-way, then resumed, matches an uninterrupted run.
big=(--threads 1 --progress never)
"$trivox" slice models/twisted_column.json -o "$tmp/killed" "${big[@]}" > /dev/null &
sleep 3
kill -9 %1 2>/dev/null || true
wait %1 2>/dev/null || true
[ ! -e "$tmp/killed/ConfigFile.xml" ] || echo "note: the job finished before the kill"
# The killed job's record: manifest.json as written at its start, and the journal of the layers
# finished since, bound to that manifest by its SHA-256; every layer listed is on disk, whole.
"$py" - "$tmp/killed" > "$tmp/journaled" <<'PY'
import sys, os, json, hashlib
d = sys.argv[1]
sha = lambda p: hashlib.sha256(open(p, "rb").read()).hexdigest()
m = json.load(open(os.path.join(d, "manifest.json")))
listed = {l["index"]: l for l in m["layers"]}
j = os.path.join(d, "manifest.journal")
if os.path.exists(j):
    text = open(j, "rb").read()
    lines = text.split(b"\n")[:-1]      # whole lines only
    head = json.loads(lines[0])
    assert head == {"trivox_journal": 1, "manifest_sha256": sha(os.path.join(d, "manifest.json"))}, head
    for line in lines[1:]:
        l = json.loads(line)
        listed[l["index"]] = l
for l in listed.values():
    assert l["sha256"] == sha(os.path.join(d, l["file"])), l["file"]
print(len(listed))
PY
"$trivox" slice models/twisted_column.json -o "$tmp/killed" "${big[@]}" --resume --json > "$tmp/killed.json"
"$py" - "$tmp/killed.json" "$(cat "$tmp/journaled")" <<'PY'
import sys, json
kept = json.load(open(sys.argv[1]))["layers_kept"]
assert kept == int(sys.argv[2]), (kept, sys.argv[2])   # --resume keeps every layer recorded
if kept == 0: print("note: the kill came before the first journal entry")
PY
[ ! -e "$tmp/killed/manifest.journal" ]
"$trivox" slice models/twisted_column.json -o "$tmp/straight" --threads 2 --progress never > /dev/null
same_folder "$tmp/straight" "$tmp/killed"
# Killed again, now while --force overwrites that finished job with another: the earlier job's
# ConfigFile.xml went first, so the folder does not look complete beside a mix of two jobs' slices.
"$trivox" slice models/twisted_column.json -o "$tmp/killed" "${big[@]}" --force --dither stochastic > /dev/null &
for _ in $(seq 200); do [ -e "$tmp/killed/ConfigFile.xml" ] || break; sleep 0.05; done   # the new job has begun
sleep 0.5
kill -9 %1 2>/dev/null || true
wait %1 2>/dev/null || true
"$py" - "$tmp/killed" <<'PY'
import sys, os, json
d = sys.argv[1]
if os.path.exists(os.path.join(d, "ConfigFile.xml")):
    m = json.load(open(os.path.join(d, "manifest.json")))
    assert m["complete"] is True and m["options"]["png.dither"] == "stochastic", "ConfigFile.xml of an unfinished job"
    print("note: the job finished before the kill")
PY

# 4. Another job in the same folder is refused, naming the difference; --force starts over.
# --force over a longer job with a VDB (88 layers) by one of 1 mm layers (44) and another
# dither leaves the folder exactly as the new job alone writes it: no stale slices, VDB or manifest.
"$trivox" slice $model -o "$tmp/forced" "${grid[@]}" --png --vdb --vdb-voxel 0.5 > /dev/null
"$trivox" slice $model -o "$tmp/forced" --dpi 100,100 --layer 1 --progress never --dither none --force > /dev/null
"$trivox" slice $model -o "$tmp/fresh" --dpi 100,100 --layer 1 --progress never --dither none > /dev/null
same_folder "$tmp/fresh" "$tmp/forced"
# Files trivox does not write stay.
echo notes > "$tmp/forced/notes.txt"
"$trivox" slice $model -o "$tmp/forced" "${grid[@]}" --force > /dev/null
[ "$(cat "$tmp/forced/notes.txt")" = notes ]
expect_fail "holds another job" "$trivox" slice $model -o "$resumed" "${grid[@]}" --zip --resume --dither none
expect_fail "png.dither was fs, now none" "$trivox" slice $model -o "$resumed" "${grid[@]}" --resume --dither none --zip
expect_fail "--resume to continue" "$trivox" slice $model -o "$resumed" "${grid[@]}" --zip
expect_fail "expected K/N" "$trivox" slice $model -o "$tmp/x" "${grid[@]}" --shard 3/3
expect_fail "expected K/N" "$trivox" slice $model -o "$tmp/x" "${grid[@]}" --shard 1
JOB_COMPLETION_INDEX=1 expect_fail "expected --shard-count N" "$trivox" slice $model -o "$tmp/x" "${grid[@]}"
SLURM_ARRAY_TASK_ID=7 SLURM_ARRAY_TASK_COUNT=3 expect_fail "SLURM_ARRAY_TASK_ID 7" "$trivox" slice $model -o "$tmp/x" "${grid[@]}"

# 5. Three shards at once into one folder, each from another source of its index; then merge.
"$trivox" slice $model -o "$sharded" "${grid[@]}" --zip --shard 0/3 > /dev/null &
SLURM_ARRAY_TASK_ID=6 SLURM_ARRAY_TASK_MIN=5 SLURM_ARRAY_TASK_COUNT=3 \
  "$trivox" slice $model -o "$sharded" "${grid[@]}" --zip > /dev/null &
JOB_COMPLETION_INDEX=2 "$trivox" slice $model -o "$sharded" "${grid[@]}" --zip --shard-count 3 > /dev/null
wait
ls "$sharded/manifest.shard-0-of-3.json" "$sharded/manifest.shard-1-of-3.json" "$sharded/manifest.shard-2-of-3.json" > /dev/null
[ ! -e "$sharded/ConfigFile.xml" ]
"$trivox" merge "$sharded" --json > "$tmp/merge.json"
mkdir "$tmp/merged"
cp "$sharded"/slice_*.png "$sharded/ConfigFile.xml" "$sharded/Mesh.stl" "$sharded/manifest.json" "$tmp/merged/"
same_folder "$tmp/whole" "$tmp/merged"
cmp "$tmp/whole.gcvf" "$tmp/s/whole.gcvf"

# 6. A shard that failed, or whose files changed, is named with what to rerun; merge changes nothing.
rm "$sharded/manifest.json" "$sharded/ConfigFile.xml"
mv "$sharded/manifest.shard-1-of-3.json" "$tmp/shard1.json"
expect_fail "rerun only --shard 1/3" "$trivox" merge "$sharded"
[ ! -e "$sharded/ConfigFile.xml" ]
[ ! -e "$sharded/manifest.json" ]
mv "$tmp/shard1.json" "$sharded/manifest.shard-1-of-3.json"
echo x >> "$sharded/slice_87.png"
expect_fail "shard 2/3: 1 file(s) missing or changed" "$trivox" merge "$sharded"
"$trivox" slice $model -o "$sharded" "${grid[@]}" --zip --shard 2/3 --resume > /dev/null
"$trivox" merge "$sharded" > /dev/null
cmp "$tmp/whole/slice_87.png" "$sharded/slice_87.png"
# 7. With the VDB: shards write VDB parts of whole leaves; the merged VDB and manifest are the
#    unsharded job's bytes; a resumed job keeps a VDB that verifies.
vdb=(--png --vdb --vdb-voxel 0.5)
"$trivox" slice $model -o "$tmp/vw/whole" "${grid[@]}" "${vdb[@]}" > /dev/null
for k in 0 1 2; do "$trivox" slice $model -o "$tmp/vs/whole" "${grid[@]}" "${vdb[@]}" --shard $k/3 > /dev/null; done
ls "$tmp/vs/whole/graded_block.shard-2-of-3.vdb" > /dev/null
"$trivox" merge "$tmp/vs/whole" > /dev/null
cmp "$tmp/vw/whole/graded_block.vdb" "$tmp/vs/whole/graded_block.vdb"
cmp "$tmp/vw/whole/manifest.json" "$tmp/vs/whole/manifest.json"
"$trivox" slice $model -o "$tmp/vw/whole" "${grid[@]}" "${vdb[@]}" --resume --json > "$tmp/vr.json"
grep -q '"vdb_kept": "graded_block.vdb"' "$tmp/vr.json"
expect_fail "png.dither was fs, now none" "$trivox" slice $model -o "$tmp/vw/whole" "${grid[@]}" "${vdb[@]}" --resume --dither none
expect_fail "vdb.voxel_mm was 0.5, now 1" "$trivox" slice $model -o "$tmp/vw/whole" "${grid[@]}" --png --vdb --vdb-voxel 1 --resume
# A volume-only job shards, merges and resumes alike (no layers, no ConfigFile.xml).
"$trivox" slice $model -o "$tmp/ow/whole" --progress never --vdb --vdb-voxel 0.5 > /dev/null
for k in 0 1; do "$trivox" slice $model -o "$tmp/os/whole" --progress never --vdb --vdb-voxel 0.5 --shard $k/2 > /dev/null; done
"$trivox" merge "$tmp/os/whole" > /dev/null
cmp "$tmp/ow/whole/graded_block.vdb" "$tmp/os/whole/graded_block.vdb"
cmp "$tmp/ow/whole/manifest.json" "$tmp/os/whole/manifest.json"
[ ! -e "$tmp/os/whole/ConfigFile.xml" ]
"$trivox" slice $model -o "$tmp/ow/whole" --progress never --vdb --vdb-voxel 0.5 --resume --json | grep -q '"vdb_kept"'

expect_fail "no shard manifests" "$trivox" merge "$tmp/whole"
expect_fail "not a folder" "$trivox" merge "$tmp/nowhere"
echo "jobs: ok"
