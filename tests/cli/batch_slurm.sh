#!/usr/bin/env bash
# gaitsim batch --slurm against a real one-node Slurm cluster started here on localhost from
# Debian's packages (munge, slurm-wlm: slurmctld, slurmd; scripts/setup.sh installs them), in a
# temporary folder with its own munge key and socket, state and spool folders and two free ports,
# no cgroups (proctrack/linuxproc, task/none). It submits a plan on the planar model (about 30 s
# on 2 cores): two tracks, a three-speed sweep from the first, a track made to fail (a broken
# model) and a prediction from it. Expected: the three independent solves in one job array, the
# others single jobs with afterok dependencies; batch-status --wait ends with the tracks and the
# sweep stopped short at their limits (exit 3), the failure failed and its dependant skipped
# (cancelled by Slurm, never run) while the independent ones went on; batch.csv agrees. The same
# plan submitted again submits only the failure and its dependant (the five that ended are kept,
# their records untouched). A long solve: submitting it again while it is queued is refused, and
# scancel stops it with its best iterate written (status interrupted), the solve receiving one
# stop signal (Slurm's SIGTERM; the job's batch process does not pass it on). Every daemon it
# started is stopped at the end.
# When Slurm is not installed or cannot start here, the test says so on stderr, leaves
# BUILD_DIR/slurm_skipped.txt with the reason (scripts/test.sh prints it) and exits 77 (CTest:
# skipped). Label: slurm.
# usage: batch_slurm.sh GAITSIM SOURCE_DIR
set -u
gaitsim=$1 src=$2
source "$(dirname "$0")/../cli_common.bash"
export OPENBLAS_NUM_THREADS=1
marker=$(dirname "$gaitsim")/slurm_skipped.txt
rm -f "$marker"
pids=()
alive() {  # alive PID: running (not gone, not a zombie)
  [ -r "/proc/$1/status" ] && ! grep -q '^State:[[:space:]]*Z' "/proc/$1/status"
}
stop_daemons() {  # SIGTERM to every daemon this script started, SIGKILL after 10 s, reaped
  local p
  for p in "${pids[@]}"; do kill -TERM "$p" 2>/dev/null; done
  for _ in $(seq 100); do
    local any=0
    for p in "${pids[@]}"; do alive "$p" && any=1; done
    [ "$any" -eq 0 ] && break
    sleep 0.1
  done
  for p in "${pids[@]}"; do kill -KILL "$p" 2>/dev/null; wait "$p" 2>/dev/null; done
}
trap 'stop_daemons; rm -rf "$work"' EXIT
skip() {  # skip REASON: loudly, and exit 77
  echo "SKIPPED: the Slurm test did not run: $1" | tee "$marker" >&2
  exit 77
}

for b in munged mungekey slurmctld slurmd sbatch squeue sinfo; do
  command -v "$b" >/dev/null || skip "$b is not installed (scripts/setup.sh installs munge and slurm-wlm)"
done
user=$(id -un) host=$(hostname -s)
mkdir -p state spool
chmod 700 "$work"
mungekey -c -k "$work/munge.key" >/dev/null 2>&1 || skip "mungekey could not create a key"
munged -F -f --socket="$work/munge.sock" --key-file="$work/munge.key" --log-file="$work/munged.log" \
  --pid-file="$work/munged.pid" --seed-file="$work/munged.seed" >munged.out 2>&1 &
pids+=($!)
# two free ports next to each other
port=$(/usr/bin/python3 -c '
import socket, random
for _ in range(200):
    p = random.randrange(20000, 60000, 2)
    try:
        for q in (p, p + 1):
            s = socket.socket(); s.bind(("127.0.0.1", q)); s.close()
        print(p); break
    except OSError:
        pass')
mem=$(($(awk '/MemTotal/ {print int($2 / 1024)}' /proc/meminfo) / 2))
cat >slurm.conf <<EOF
ClusterName=gaitsimtest
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$port
SlurmdPort=$((port + 1))
SlurmUser=$user
SlurmdUser=$user
AuthType=auth/munge
AuthInfo=socket=$work/munge.sock
CredType=cred/munge
StateSaveLocation=$work/state
SlurmdSpoolDir=$work/spool
SlurmctldPidFile=$work/slurmctld.pid
SlurmdPidFile=$work/slurmd.pid
SlurmctldLogFile=$work/slurmctld.log
SlurmdLogFile=$work/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
MpiDefault=none
ReturnToService=2
NodeName=$host NodeAddr=127.0.0.1 CPUs=$(nproc) RealMemory=$mem State=UNKNOWN
PartitionName=debug Nodes=ALL Default=YES MaxTime=INFINITE State=UP
EOF
export SLURM_CONF=$work/slurm.conf
for _ in $(seq 50); do [ -S munge.sock ] && break; sleep 0.1; done
slurmctld -D -i -f "$SLURM_CONF" >slurmctld.out 2>&1 &
pids+=($!)
slurmd -D -f "$SLURM_CONF" >slurmd.out 2>&1 &
pids+=($!)
for _ in $(seq 60); do [ "$(sinfo -h -o %T 2>/dev/null)" = idle ] && break; sleep 0.5; done
if [ "$(sinfo -h -o %T 2>/dev/null)" != idle ]; then
  tail -n 5 munged.out slurmctld.out slurmd.out slurmctld.log slurmd.log >&2 2>/dev/null
  skip "the one-node cluster did not come up (node state '$(sinfo -h -o %T 2>&1)')"
fi
echo "slurm: one-node cluster up on $host:$port ($(nproc) CPUs)"

trial=$src/mjmodels/trials/jw_ngait_og5
echo '<mujoco><worldbody><body><joint type="bogus"/></body></worldbody></mujoco>' >bad.xml
cat >plan.json <<EOF
{"model": "$src/mjmodels/gait2d.xml",
 "options": {"nodes": 5, "threads": 1, "max-iter": 10, "refine": 0},
 "slurm": {"time_min": 10},
 "solves": [
  {"name": "t1", "track": "$trial"},
  {"name": "t2", "track": "$trial", "options": {"weight": ["grf=5"]}},
  {"name": "up", "sweep": [1.2, 1.4, 1.6], "guess": "t1", "start": "neighbour", "options": {"max-iter": 3}},
  {"name": "bad", "track": "$trial", "options": {"model": "bad.xml"}},
  {"name": "after_bad", "predict": 1.2, "guess": "bad"}]}
EOF
out=$work/out
"$gaitsim" batch plan.json --out "$out" --slurm >submit1.txt 2>&1
status=$?
check "submitted: exit 0 (got $status)" test "$status" -eq 0
check "jobs: one array of the three independent solves, single jobs for the others" \
  /usr/bin/python3 - "$out/slurm/jobs.json" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
arr = {j[n].split("_")[0] for n in ("t1", "t2", "bad")}
ok = (len(j) == 7 and len(arr) == 1 and sorted(j[n].split("_")[1] for n in ("t1", "t2", "bad")) == ["0", "1", "2"]
      and all("_" not in j[n] for n in ("up_1.2", "up_1.4", "up_1.6", "after_bad")))
if not ok:
    print(j, file=sys.stderr)
sys.exit(0 if ok else 1)
PY
check "up_1.4 waits for up_1.2's job" grep -q "job .*: up_1.4 .*afterok:$(/usr/bin/python3 -c \
  'import json,sys; print(json.load(open(sys.argv[1]))["up_1.2"])' "$out/slurm/jobs.json")" submit1.txt
timeout 300 "$gaitsim" batch-status "$out" --wait >status1.txt 2>&1
status=$?
check "batch-status --wait: exit 0 (got $status)" test "$status" -eq 0
check "statuses" test "$(awk '{print $1 ":" $2}' status1.txt | tr '\n' ' ')" = \
  "t1:stopped t2:stopped up_1.2:stopped up_1.4:stopped up_1.6:stopped bad:failed after_bad:skipped "
check "the skipped solve never ran" test ! -e "$out/logs/after_bad.json"
check "batch.csv: records of the five that ended, the failure, the skipped one" \
  /usr/bin/python3 - "$out" <<'PY'
import csv, json, sys
d = sys.argv[1]
rows = {r["solve"]: r for r in csv.DictReader(open(f"{d}/batch.csv"))}
ok = rows["bad"]["status"] == "failed" and rows["after_bad"]["status"] == "skipped"
for n in ("t1", "t2", "up_1.2", "up_1.4", "up_1.6"):
    rec = json.load(open(f"{d}/logs/{n}.json"))
    s = json.load(open(f"{d}/{n}/summary.json"))
    ok &= rows[n]["status"] == "stopped short" and rec["exit"] == 3
    ok &= abs(float(rows[n]["wall_s"]) - rec["wall_s"]) <= 0.05
    ok &= abs(float(rows[n]["stride_time_s"]) - s["stride_time_s"]) <= 1e-4
    if n.startswith("up_"):
        ok &= abs(s["speed_mps"] - float(n[3:])) <= max(1e-4, s["max_violation"])
if not ok:
    print(rows, file=sys.stderr)
sys.exit(0 if ok else 1)
PY

# the same plan again: only the failure and its dependant are submitted
cp "$out/logs/t1.json" t1_record.json
"$gaitsim" batch plan.json --out "$out" --slurm >submit2.txt 2>&1
status=$?
check "again: exit 0 (got $status)" test "$status" -eq 0
check "again: five kept, two submitted" grep -q '^batch: 7 solves, 5 kept from an earlier run, 2 to submit' submit2.txt
timeout 120 "$gaitsim" batch-status "$out" --wait >status2.txt 2>&1
check "again: the same statuses" cmp -s status1.txt status2.txt
check "again: t1 not redone" cmp -s t1_record.json "$out/logs/t1.json"

# a long solve: a second submission while it is queued is refused; scancel (SIGTERM to every
# process of the job) stops it with its best iterate written
cat >long.json <<EOF
{"model": "$src/mjmodels/gait2d.xml",
 "solves": [{"name": "long", "track": "$trial",
             "options": {"nodes": 10, "threads": 1, "max-iter": 5000, "refine": 0}}]}
EOF
"$gaitsim" batch long.json --out "$work/lo" --slurm >submit3.txt 2>&1
check "long: submitted" test $? -eq 0
err=$("$gaitsim" batch long.json --out "$work/lo" --slurm 2>&1 >/dev/null)
status=$?
check "long: a second submission while queued: exit 1 (got $status)" test "$status" -eq 1
check "long: one line naming the queued solve" grep -q '^gaitsim: long.json: 1 solves of an earlier submission are still queued or running (long)' <<<"$err"
for _ in $(seq 600); do grep -q '^iter' "$work/lo/logs/long.log" 2>/dev/null && break; sleep 0.1; done
scancel "$(/usr/bin/python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["long"])' "$work/lo/slurm/jobs.json")"
timeout 120 "$gaitsim" batch-status "$work/lo" --wait >status3.txt 2>&1
check "long: scancel: interrupted" test "$(awk '{print $2}' status3.txt)" = interrupted
check "long: scancel: the best iterate written" /usr/bin/python3 - "$work/lo/long" <<'PY'
import json, sys
r = json.load(open(sys.argv[1] + "/../logs/long.json"))
s = json.load(open(sys.argv[1] + "/summary.json"))
ok = r["interrupted"] and r["exit"] == 3 and s["iterations"] < 5000
if not ok:
    print(r, s.get("iterations"), file=sys.stderr)
sys.exit(0 if ok else 1)
PY
n=$(grep -c 'stop signal' "$work/lo/logs/long.log")
check "long: scancel: one stop signal reached the solve (got $n)" test "$n" -eq 1

stop_daemons
gone() { local p; for p in "${pids[@]}"; do if kill -0 "$p" 2>/dev/null; then return 1; fi; done; }
check "every daemon stopped" gone
pids=()
finish
