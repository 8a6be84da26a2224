#!/usr/bin/env bash
# Kubernetes, as far as trivox can tell: the Indexed Job of docs/jobs.md, read from that page,
# and its pods' commands run with the environment Kubernetes gives a pod of an Indexed Job
# (JOB_COMPLETION_INDEX = the pod's index, HOSTNAME = <job>-<index>-<suffix>), all 8 at once
# into one folder as parallelism 8 runs them, then the merge Job's command.
# Truths: the slice Job is Indexed, with --shard-count equal to its completions and
# parallelism; the merged folder is, byte for byte, the folder of one unsharded job; a pod run
# again (a retry of a failed index) changes nothing; the index without the count is refused.
set -euo pipefail
source "$(dirname "$0")/../cli/lib.bash" "$@"
trivox=$(cd "$(dirname "$trivox")" && pwd)/$(basename "$trivox")
model="$tmp/quickstart.json"
"$trivox" build models/quickstart.json -o "$model" > /dev/null
"$trivox" slice "$model" -o "$tmp/whole" --progress never > /dev/null

"$py" - docs/jobs.md "$trivox" "$model" "$tmp/job" <<'PY'
import sys, re, os, subprocess
import yaml
doc, trivox, model, folder = sys.argv[1:]
block = re.search(r"### Kubernetes\n.*?```yaml\n(.*?)```", open(doc).read(), re.S).group(1)
slice_job, merge_job = list(yaml.safe_load_all(block))
for j in (slice_job, merge_job):
    assert j["apiVersion"] == "batch/v1" and j["kind"] == "Job", j
    assert j["spec"]["template"]["spec"]["restartPolicy"] == "Never"
spec = slice_job["spec"]
n = spec["completions"]
assert spec["completionMode"] == "Indexed" and spec["parallelism"] == n, spec
[pod] = spec["template"]["spec"]["containers"]
cmd = pod["command"]
assert cmd[cmd.index("--shard-count") + 1] == str(n), cmd
# Both Jobs mount the same claim at the same place.
claim = lambda j: j["spec"]["template"]["spec"]["volumes"][0]["persistentVolumeClaim"]["claimName"]
mount = lambda j: j["spec"]["template"]["spec"]["containers"][0]["volumeMounts"][0]["mountPath"]
assert claim(slice_job) == claim(merge_job) and mount(slice_job) == mount(merge_job) == "/shared"

def local(c):
    return [trivox if a == "trivox" else a.replace("/shared/teapot.json", model).replace("/shared/teapot", folder) for a in c]

base = {k: v for k, v in os.environ.items() if not k.startswith(("SLURM_", "JOB_COMPLETION_INDEX"))}
def pod_env(i):
    return dict(base, JOB_COMPLETION_INDEX=str(i), HOSTNAME=f"{slice_job['metadata']['name']}-{i}-x7k2p")
# parallelism n: every pod at once, into one folder.
pods = [subprocess.Popen(local(cmd), env=pod_env(i), stdout=subprocess.DEVNULL, stderr=subprocess.PIPE) for i in range(n)]
for i, p in enumerate(pods):
    _, err = p.communicate()
    assert p.returncode == 0, (i, err.decode())
# A failed pod is retried with its index: the shard is redone, the same bytes.
r = subprocess.run(local(cmd), env=pod_env(3), capture_output=True, text=True)
assert r.returncode == 0, r.stderr
[merge] = merge_job["spec"]["template"]["spec"]["containers"]
r = subprocess.run(local(merge["command"]), env=base, capture_output=True, text=True)
assert r.returncode == 0, r.stderr
# The index without the count: refused, naming what is missing.
bad = [a for k, a in enumerate(cmd) if a != "--shard-count" and (k == 0 or cmd[k - 1] != "--shard-count")]
r = subprocess.run(local(bad[:-2]) + ["--progress", "never"], env=pod_env(0), capture_output=True, text=True)
assert r.returncode == 2 and "JOB_COMPLETION_INDEX" in r.stderr, (r.returncode, r.stderr)
PY
for f in "$tmp/whole"/*; do cmp "$f" "$tmp/job/$(basename "$f")"; done
[ "$(ls "$tmp/job" | grep -v '^manifest\.shard-' | wc -l)" -eq "$(ls "$tmp/whole" | wc -l)" ]
echo "kubernetes: ok"
