#!/usr/bin/env bash
# A real scheduler: a single-node Slurm cluster (Debian's slurm-wlm and munge, started here in a
# folder of the test's own, on ports of its own) runs the Slurm lines of docs/jobs.md as printed
# there, with the model, folder and trivox of the test put in.
# Truths: the array of 8 shards and the dependent merge write, byte for byte, the folder of one
# unsharded job (cmp, every file but the shards' manifest parts); a shard lost afterwards is named
# by `trivox merge` (exit 2, nothing written), and the documented rerun of that shard alone plus a
# merge make the folder whole again, the same bytes.
# Skipped (exit 77) when Slurm or munge is not installed (tools/setup.sh installs them) or when not
# run as root (slurmd must start jobs as their users).
set -euo pipefail
source "$(dirname "$0")/../cli/lib.bash" "$@"
for tool in slurmctld slurmd munged sbatch squeue scontrol; do
  command -v $tool > /dev/null || { echo "$tool is not installed: skipped (tools/setup.sh installs it)"; exit 77; }
done
[ "$(id -u)" -eq 0 ] || { echo "not root: skipped (slurmd runs jobs as their users)"; exit 77; }
trivox=$(cd "$(dirname "$trivox")" && pwd)/$(basename "$trivox")
chmod 755 "$tmp"
model="$tmp/quickstart.json"      # the quick start's scene, built into a model
"$trivox" build models/quickstart.json -o "$model" > /dev/null

# --- The cluster: munge with its own key and socket, slurmctld and slurmd on one node. --------
c="$tmp/cluster"
mkdir -p "$c/spool" "$c/state" "$c/munge"
head -c 128 /dev/urandom > "$c/munge/munge.key"
chmod 400 "$c/munge/munge.key"
munged --force --key-file="$c/munge/munge.key" --socket="$c/munge/socket" --pid-file="$c/munge/pid" \
  --log-file="$c/munge/log" --seed-file="$c/munge/seed"
node=$(hostname -s)
port=$((20000 + RANDOM % 20000))
cat > "$c/slurm.conf" <<CONF
ClusterName=trivoxtest
SlurmctldHost=$node
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$c/munge/socket
CredType=cred/munge
StateSaveLocation=$c/state
SlurmdSpoolDir=$c/spool
SlurmctldPidFile=$c/slurmctld.pid
SlurmdPidFile=$c/slurmd.pid
SlurmctldPort=$port
SlurmdPort=$((port + 1))
SlurmctldLogFile=$c/slurmctld.log
SlurmdLogFile=$c/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
MpiDefault=none
ReturnToService=2
MinJobAge=600
SchedulerType=sched/builtin
SchedulerParameters=sched_interval=1
NodeName=$node CPUs=$(nproc) State=UNKNOWN
PartitionName=test Nodes=$node Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF="$c/slurm.conf"
stop_cluster() {
  scontrol shutdown > /dev/null 2>&1 || true
  [ -f "$c/munge/pid" ] && kill "$(cat "$c/munge/pid")" 2> /dev/null || true
  sleep 0.5
  rm -rf "$tmp"
}
trap stop_cluster EXIT
slurmctld -f "$c/slurm.conf"
slurmd -f "$c/slurm.conf"
for i in $(seq 100); do sinfo -h -o %T 2> /dev/null | grep -q idle && break; sleep 0.2; done
sinfo -h -o %T | grep -q idle || { echo "the Slurm node did not come up"; cat "$c"/*.log; exit 1; }

# wait_jobs ID...: until Slurm has finished them; fails unless each exited 0.
wait_jobs() {
  for id in "$@"; do
    for i in $(seq 900); do [ -z "$(squeue -h -j "$id" 2> /dev/null)" ] && break; sleep 0.2; done
    scontrol show job "$id" | grep -o "JobState=[A-Z]*" | sort -u | grep -qx "JobState=COMPLETED" ||
      { echo "Slurm job $id did not complete:"; scontrol show job "$id" | grep -E "JobId|JobState"; tail -n 5 "$tmp"/*.slurm-*.out; exit 1; }
  done
}

# --- The lines of docs/jobs.md, with this test's model, folder and trivox. ---------------------
"$py" - docs/jobs.md "$trivox" "$model" "$tmp/job" > "$tmp/lines.sh" <<'PY'
import sys, re
doc, trivox, model, folder = sys.argv[1:]
text = open(doc).read()
block = re.search(r"### Slurm\n\n```sh\n(.*?)```", text, re.S).group(1)
lines = [l for l in block.splitlines() if l.strip() and not l.startswith("#")]
assert len(lines) == 3, lines
out = []
for l in lines:
    l = l.replace('"trivox ', '"' + trivox + ' ').replace("teapot.json", model).replace("/shared/teapot", folder)
    # Slurm writes each job's output in the folder it was submitted from: keep it in the test's.
    out.append(l.replace("sbatch ", "sbatch --output=" + folder + ".slurm-%j-%a.out ", 1))
print("\n".join(out))
PY
mapfile -t lines < "$tmp/lines.sh"
cd "$tmp"
eval "${lines[0]}"                 # array=$(sbatch ... --array=0-7 ...)
merge=$(eval "${lines[1]}")
wait_jobs "$array" "$merge"

# One unsharded job: the reference.
"$trivox" slice "$model" -o "$tmp/whole" --progress never > /dev/null
same() {
  for f in "$tmp/whole"/*; do cmp "$f" "$tmp/job/$(basename "$f")"; done
  [ "$(ls "$tmp/job" | grep -v '^manifest\.shard-' | wc -l)" -eq "$(ls "$tmp/whole" | wc -l)" ]
}
same
[ "$(ls "$tmp/job" | grep -c '^manifest\.shard-.*-of-8\.json$')" -eq 8 ]

# --- A shard lost: merge names it; the documented rerun alone, then a merge, make it whole. ----
rm "$tmp/job/manifest.shard-5-of-8.json" "$tmp/job/manifest.json" "$tmp/job/ConfigFile.xml"
expect_fail "--shard 5/8" "$trivox" merge "$tmp/job"
[ ! -e "$tmp/job/ConfigFile.xml" ]
rerun=$(eval "${lines[2]}")
merge=$(eval "${lines[1]/\$array/$rerun}")
wait_jobs "$rerun" "$merge"
same
echo "slurm: ok"
